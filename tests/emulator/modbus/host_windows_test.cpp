// Whole points through profiles of devices synbench did not write, against the twin behind the
// emulator's register server, in-process on virtual time: drives without window signals (the
// bench keeps their windows from telemetry polled every 50 ms) and a totalizer meter whose u32
// counters wrap during the window, or a power meter; each compared with the same operating
// point measured with the drives' own windows and synbench's gated meter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bench/point_procedure.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"

#ifndef SYNBENCH_TEST_PROFILE_DIR
#error "SYNBENCH_TEST_PROFILE_DIR must name tests/drivers/profiles"
#endif

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using drivers::DeviceProfile;

DeviceProfile default_profile(DeviceKind k) { return *drivers::load_device_profile(drivers::default_profile_path(k)).profile; }
DeviceProfile test_profile(const char* file) {
  auto r = drivers::load_device_profile(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / file);
  if (!r.profile) throw std::runtime_error(std::string(file) + " does not parse");
  return *r.profile;
}

struct Measured {
  bench::PointRecord record;
  std::string error;
  int wraps = -1;                          // totalizer: counters that wrapped in the window
  std::uint64_t open_counts[3] = {0, 0, 0};  // totalizer: counters at the window's open
};

// One point at 600 rpm, 1.5 N m, 55 deg, a 1 s window, through `profiles` (SynRM, load,
// meter) on a fresh twin; `counter_start` presets the twin's free-running counters.
Measured measure(std::vector<DeviceProfile> profiles, const std::uint64_t (&counter_start)[3] = {0, 0, 0}) {
  TwinService service{TwinConfig{}, profiles};
  service.locked([&](auto&, TwinSignals& s, auto&) {
    s.instruments().set_counter_start(counter_start[0], counter_start[1], counter_start[2]);
  });
  TwinRegisterBus bus{service};
  TwinServiceClock clock{service};
  drivers::ProfileBench bench{bus, profiles[0], bus, profiles[1], bus, profiles[2], clock};
  bench::PointRequest req;
  req.speed_rpm = 600;
  req.load_Nm = 1.5;
  req.angle_deg = 55;
  req.window_s = 1.0;
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = TwinConfig{}.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  const auto proc = bench::run_point(bench.devices(), bench.clock(), req, opt);
  Measured m{proc.record(), proc.error()};
  if (const auto* t = bench.meter().totalizer()) {
    m.wraps = t->wraps();
    for (int i = 0; i < 3; ++i) m.open_counts[i] = t->open_counts()[i];
  }
  EXPECT_TRUE(proc.has_record()) << proc.error();
  return m;
}

std::vector<DeviceProfile> device_windows() {
  return {default_profile(DeviceKind::synrm_drive), default_profile(DeviceKind::load_drive),
          default_profile(DeviceKind::vfc_meter)};
}
std::vector<DeviceProfile> host_windows(const char* meter) {
  return {test_profile("synrm_host_window.json"), test_profile("load_host_window.json"), test_profile(meter)};
}

void print(const char* what, const bench::PointRecord& r) {
  std::printf("%-22s %s window, %u samples, %.6f s: speed %.3f rpm, udc %.3f V, pdcm %.3f W, pdcg %.3f W, "
              "pm %.3f W, efficiency %.5f\n",
              what, drivers::keeper_name(r.window_source), r.samples, r.window_s, r.speed_meas_rpm, r.udc_V,
              r.pdcm_W, r.pdcg_W, r.pm_W, r.efficiency);
}

// How far a host-kept point may differ from the device-kept one at the same operating point, and
// why. The procedure runs the same timeline on both (virtual time, same requests), so the
// windows cover the same second of the same plant; the meters count the same converters
// (twin_instruments.hpp). What differs: on the drives' side 21 polls of filtered telemetry
// instead of 10000 control periods (the speed loop's and the DC link's ripple, sampled 21
// times: below 0.05 % of P_m and P_dc at a steady point), a speed from the filtered speed_rpm
// instead of encoder counts, and the 0.1 V quantum of udc_V's register (0.024 % of 425 V); on
// the meter's side the totalizer's 1 count in 7e5 and 1 tick in 1e6 (1e-6), or the power
// meter's 20 ms intervals, which overlap the window's edges by up to one interval each (2 % of
// the window at the ripple of a steady point, well below 0.1 %), each quantised to 1 pulse per
// interval (0.5 mA, 0.05 % at 1 A). 0.2 % of each power and 0.002 of efficiency (0.3 % of 0.65)
// hold that with margin; a sum not divided, a window of the wrong length, or a counter
// difference taken without the wrap misses it by orders of magnitude.
constexpr double kPowerTolerance = 0.002;
constexpr double kEfficiencyTolerance = 0.002;

void expect_agree(const bench::PointRecord& host, const bench::PointRecord& device) {
  EXPECT_NEAR(host.efficiency, device.efficiency, kEfficiencyTolerance);
  EXPECT_NEAR(host.pdcm_W, device.pdcm_W, kPowerTolerance * device.pdcm_W);
  EXPECT_NEAR(host.pdcg_W, device.pdcg_W, kPowerTolerance * std::fabs(device.pdcm_W));
  EXPECT_NEAR(host.pm_W, device.pm_W, kPowerTolerance * device.pm_W);
  EXPECT_NEAR(host.speed_meas_rpm, 600, 3);
}

TEST(HostWindows, APointThroughHostWindowsAndAWrappingTotalizerAgreesWithTheDeviceWindows) {
  const Measured device = measure(device_windows());
  print("device windows, gate", device.record);
  ASSERT_TRUE(device.error.empty()) << device.error;
  EXPECT_EQ(device.record.window_source, drivers::WindowKeeper::device);
  EXPECT_EQ(device.record.samples, 10000u);

  // First with the counters from 0, to learn where they stand at the window's open; then the
  // same point on a fresh twin (deterministic: same plant, noise seeds and requests) with the
  // counters preset so that each wraps halfway through the window.
  const Measured probe = measure(host_windows("meter_totalizer.json"));
  ASSERT_TRUE(probe.error.empty()) << probe.error;
  EXPECT_EQ(probe.wraps, 0);
  const std::uint64_t range = std::uint64_t{1} << 32;
  const double half[3] = {probe.record.idcm_A * 1e5 * 0.5 + 0.25e6, probe.record.idcg_A * 1e5 * 0.5 + 0.25e6, 0.5e6};
  std::uint64_t start[3];
  for (int i = 0; i < 3; ++i) start[i] = range - probe.open_counts[i] - static_cast<std::uint64_t>(half[i]);
  const Measured wrapped = measure(host_windows("meter_totalizer.json"), start);
  print("host windows, totalizer", wrapped.record);
  ASSERT_TRUE(wrapped.error.empty()) << wrapped.error;
  EXPECT_EQ(wrapped.wraps, 3);  // all three counters crossed 2^32 during the window
  EXPECT_EQ(wrapped.record.window_source, drivers::WindowKeeper::host);
  EXPECT_EQ(wrapped.record.samples, 21u);  // 1 s at 50 ms, both ends
  // The wrap changes nothing: the same counts as from 0.
  EXPECT_DOUBLE_EQ(wrapped.record.idcm_A, probe.record.idcm_A);
  EXPECT_DOUBLE_EQ(wrapped.record.efficiency, probe.record.efficiency);
  EXPECT_NEAR(wrapped.record.window_s, 1.0, 1e-3);
  expect_agree(wrapped.record, device.record);
}

TEST(HostWindows, APointThroughHostWindowsAndAPowerMeterAgreesWithTheDeviceWindows) {
  const Measured device = measure(device_windows());
  const Measured power = measure(host_windows("meter_power.json"));
  print("host windows, power", power.record);
  ASSERT_TRUE(power.error.empty()) << power.error;
  EXPECT_EQ(power.record.window_source, drivers::WindowKeeper::host);
  expect_agree(power.record, device.record);
}

// A drive without temp_C has no winding temperature: the record says null, not 0 degC, and a
// point asked to hold a thermal precondition fails naming the signal instead of warming blind
// (the sweep refuses such a plan before its start: app/plan_needs.hpp).
TEST(HostWindows, NoTemperatureIsNullAndAThermalPreconditionFailsNamingTempC) {
  const Measured host = measure(host_windows("meter_totalizer.json"));
  EXPECT_FALSE(host.record.temp_C);
  auto profiles = host_windows("meter_totalizer.json");
  TwinService service{TwinConfig{}, profiles};
  TwinRegisterBus bus{service};
  TwinServiceClock clock{service};
  drivers::ProfileBench bench{bus, profiles[0], bus, profiles[1], bus, profiles[2], clock};
  bench::PointRequest req;
  req.speed_rpm = 600;
  req.load_Nm = 1.5;
  bench::PointOptions opt;
  opt.thermal = bench::PointOptions::Thermal{};
  const auto proc = bench::run_point(bench.devices(), bench.clock(), req, opt);
  EXPECT_EQ(proc.phase(), bench::PointPhase::failed);
  EXPECT_FALSE(proc.has_record());
  EXPECT_NE(proc.error().find("temp_C"), std::string::npos) << proc.error();
  drivers::LoadTelemetry lt;
  ASSERT_FALSE(bench.load().read(lt));
  EXPECT_LT(lt.torque_Nm, 0.1);  // stopped in order, not warmed at 3.5 N m
}

}  // namespace
}  // namespace synbench::emulator
