// A window's batches over real Modbus (TCP on loopback, RTU through socat pseudo-terminals)
// from the twin's register server with the default profiles: the profile devices read B batch
// means per drive quantity that average to the window's mean within the register's resolution
// (f32), B sub-gate counts per meter channel that sum to the gate's counts exactly, and the
// meter's calibration with them.
#include <gtest/gtest.h>

#include <numeric>

#include "drivers/profile_devices/profile_bench.hpp"
#include "drivers/real_time_clock.hpp"
#include "tests/drivers/bus/modbus_link_fixture.hpp"

namespace synbench::drivers {
namespace {

namespace t = synbench::testing;

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }

std::uint64_t sum(const std::vector<std::uint64_t>& v) { return std::accumulate(v.begin(), v.end(), std::uint64_t{0}); }

void window_with_batches(RegisterBus& bus, t::Emulator& emu) {
  const std::vector<DeviceProfile>& profiles = emu.profiles;
  RealTimeClock clock;
  ProfileBench bench(bus, profiles[0], bus, profiles[1], bus, profiles[2], clock);
  ASSERT_FALSE(bench.load().set_torque_Nm(1.0));
  ASSERT_FALSE(bench.load().enable(true));
  ASSERT_FALSE(bench.synrm().set_angle_deg(54));
  ASSERT_FALSE(bench.synrm().set_speed_rpm(400));
  ASSERT_FALSE(bench.synrm().enable(true));
  bench.clock().wait_until(clock.now_s() + 1.5);
  ASSERT_FALSE(bench.trigger().open_window(0.5)) << bus.last_error();
  const double deadline = clock.now_s() + 5;
  while (!bench.trigger().window_closed() && clock.now_s() < deadline) bench.clock().wait_until(clock.now_s() + 0.02);
  SynrmWindow w;
  LoadWindow l;
  MeterReading m;
  ASSERT_FALSE(bench.synrm().read_window(w)) << bench.synrm().error_detail();
  ASSERT_FALSE(bench.load().read_window(l)) << bench.load().error_detail();
  ASSERT_FALSE(bench.meter().read(m)) << bench.meter().error_detail();
  const std::size_t b = static_cast<std::size_t>(emulator::TwinConfig{}.firmware.window_batches);
  EXPECT_EQ(w.samples, 5000u);
  ASSERT_EQ(w.batch_im_A.size(), b);
  ASSERT_EQ(w.batch_speed_meas_rpm.size(), b);
  ASSERT_EQ(l.batch_torque_Nm.size(), b);
  ASSERT_EQ(m.batch_counts_m.size(), b);
  ASSERT_EQ(m.batch_counts_g.size(), b);
  // f32 registers: 24-bit mantissas.
  EXPECT_NEAR(mean(w.batch_im_A), w.im_A, 1e-6 * w.im_A);
  EXPECT_GT(w.im_A, 0.5);
  EXPECT_NEAR(mean(w.batch_speed_meas_rpm), w.speed_meas_rpm, 0.1);  // a count per batch: 0.03 rpm
  EXPECT_NEAR(w.speed_meas_rpm, 400, 5);
  EXPECT_NEAR(mean(l.batch_torque_Nm), l.torque_Nm, 1e-6 * l.torque_Nm);
  EXPECT_NEAR(l.torque_Nm, 1.0, 0.05);
  EXPECT_EQ(sum(m.batch_counts_m), m.counts_m);
  EXPECT_EQ(sum(m.batch_counts_g), m.counts_g);
  // Real counts, not copies of the mean: exactly what the meter latched at its sub-gates (in a
  // steady state two batches may well hold the same count, so compare with the far side).
  const MeterReading far = emu.service.locked([](emulator::Twin& twin, auto&, auto&) { return twin.meter_reading(); });
  EXPECT_EQ(m.batch_counts_m, far.batch_counts_m);
  EXPECT_EQ(m.batch_counts_g, far.batch_counts_g);
  EXPECT_EQ(m.counts_m, far.counts_m);
  EXPECT_EQ(m.f0_Hz, emulator::TwinConfig{}.vfc.f0_Hz);
  EXPECT_EQ(m.kf_Hz_per_A, emulator::TwinConfig{}.vfc.kf_Hz_per_A);
  EXPECT_NEAR(m.idcm_A, (static_cast<double>(m.counts_m) / m.gate_s - m.f0_Hz) / m.kf_Hz_per_A, 1e-5);
  ASSERT_FALSE(bench.synrm().enable(false));
  ASSERT_FALSE(bench.load().enable(false));
}

TEST(BatchesOverModbus, Tcp) {
  t::Emulator emu;
  ModbusTcpBus bus({"127.0.0.1", emu.start_tcp()}, t::link_options(0.5));
  window_with_batches(bus, emu);
}

TEST(BatchesOverModbus, Rtu) {
  t::SocatPair pty("batches");
  if (!pty.ok()) GTEST_SKIP() << "socat is not available";
  t::Emulator emu;
  ASSERT_TRUE(emu.start_rtu(pty.a()));
  RtuPort port;
  port.device = pty.b();
  ModbusRtuBus bus(port, t::link_options(0.5));
  window_with_batches(bus, emu);
}

}  // namespace
}  // namespace synbench::drivers
