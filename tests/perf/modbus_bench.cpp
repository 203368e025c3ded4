// Register transactions per second over Modbus TCP on loopback through synbench's driver stack,
// as a ratio to a plain libmodbus loop against the same server in the same run (target >= 0.8).
// Two levels: the bus (ModbusTcpBus::read_registers vs modbus_read_registers, 5 holding
// registers) and the device (ProfileSynrmDrive::read, three requests decoded with limits, vs
// the same three plain libmodbus reads). Rounds alternate and the medians are compared, so
// drift of the machine hits both sides alike.
// usage: modbus_bench [--round-s S] [--rounds N]
#include <modbus.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/profile_devices/profile_drives.hpp"
#include "emulator/modbus/tcp_server.hpp"
#include "emulator/modbus/twin_service.hpp"

namespace {

using namespace synbench;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Runs `body` (which returns the transactions it made) for `seconds`; transactions per second.
double rate(double seconds, const std::function<int()>& body) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  long n = 0;
  double elapsed = 0;
  do {
    for (int i = 0; i < 50; ++i) n += body();
    elapsed = std::chrono::duration<double>(clock::now() - start).count();
  } while (elapsed < seconds);
  return static_cast<double>(n) / elapsed;
}

}  // namespace

int main(int argc, char** argv) {
  double round_s = 0.5;
  int rounds = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--round-s")) round_s = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::max(1, std::atoi(argv[i + 1]));
  }

  std::vector<drivers::DeviceProfile> profiles;
  for (auto k : drivers::kDeviceKinds)
    profiles.push_back(*drivers::load_device_profile(drivers::default_profile_path(k)).profile);
  emulator::TwinService service(emulator::TwinConfig{}, profiles);
  service.start_realtime(1.0);
  emulator::FaultInjector faults;
  emulator::ModbusTcpServer server(service, faults);
  std::string error;
  if (!server.start("127.0.0.1", 0, error)) {
    std::fprintf(stderr, "modbus_bench: %s\n", error.c_str());
    return 1;
  }

  modbus_t* plain = modbus_new_tcp("127.0.0.1", server.port());
  modbus_set_slave(plain, 1);
  if (modbus_connect(plain) == -1) {
    std::fprintf(stderr, "modbus_bench: connect: %s\n", modbus_strerror(errno));
    return 1;
  }
  drivers::ModbusTcpBus bus({"127.0.0.1", server.port()});
  drivers::ProfileSynrmDrive drive(bus, profiles[0]);

  std::uint16_t words[32];
  std::uint8_t bits[1];
  bool failed = false;
  const auto plain_bus = [&] {
    failed |= modbus_read_registers(plain, 16, 5, words) != 5;
    return 1;
  };
  const auto stack_bus = [&] {
    failed |= static_cast<bool>(bus.read_registers(1, drivers::RegisterKind::holding, 16, std::span(words, 5)));
    return 1;
  };
  const auto plain_device = [&] {
    failed |= modbus_read_input_registers(plain, 0, 2, words) != 2;
    failed |= modbus_read_input_registers(plain, 16, 16, words) != 16;
    failed |= modbus_read_input_bits(plain, 0, 1, bits) != 1;
    return 3;
  };
  drivers::SynrmTelemetry t;
  const auto stack_device = [&] {
    failed |= static_cast<bool>(drive.read(t));
    return 3;
  };

  std::vector<double> pb, sb, pd, sd;
  for (int r = 0; r < rounds; ++r) {
    pb.push_back(rate(round_s, plain_bus));
    sb.push_back(rate(round_s, stack_bus));
    pd.push_back(rate(round_s, plain_device));
    sd.push_back(rate(round_s, stack_device));
  }
  modbus_close(plain);
  modbus_free(plain);
  server.stop();
  service.stop();
  if (failed) {
    std::fprintf(stderr, "modbus_bench: a transaction failed: %s\n", bus.last_error().c_str());
    return 1;
  }
  const double bus_ratio = median(sb) / median(pb), device_ratio = median(sd) / median(pd);
  std::printf("Modbus TCP loopback, median of %d rounds of %.2f s (transactions per second):\n", rounds, round_s);
  std::printf("  read 5 holding registers:   plain libmodbus %8.0f   ModbusTcpBus      %8.0f   ratio %.3f\n",
              median(pb), median(sb), bus_ratio);
  std::printf("  SynRM telemetry (3 reads):  plain libmodbus %8.0f   ProfileSynrmDrive %8.0f   ratio %.3f\n",
              median(pd), median(sd), device_ratio);
  std::printf("target ratio >= 0.8: %s\n", std::min(bus_ratio, device_ratio) >= 0.8 ? "met" : "NOT met");
  return 0;
}
