// A fault code the bench's profile has no label for, read through the profile from the twin's
// register server: it reaches the safety supervisor as the fault "unknown" with the device's
// code, is recorded so, and ends in the ordered stop (the load comes off, the shaft stops),
// where a decode error used to leave the load braking. And a value that cannot be decoded at all
// fails the point with a message that says where.
#include "bench/safety_supervisor.hpp"
#include "bench/point_procedure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"

namespace synbench::bench {
namespace {

using drivers::DeviceKind;
using json = synbench::Json;
namespace t = synbench::testing;

TEST(UnknownFault, StopsTheBenchInOrderAndCarriesTheDevicesCode) {
  // The drive reports an over-current as 0x2310; the bench's profile does not list that code.
  json used = t::vendor_synrm(t::pulse_reset(100), json());
  used["signals"]["fault_code"]["values"].erase("overcurrent");
  std::vector<drivers::DeviceProfile> served{
      t::parse_or_throw(t::vendor_synrm(t::pulse_reset(100), json())),
      t::parse_or_throw(t::default_profile_doc(DeviceKind::load_drive)),
      t::parse_or_throw(t::default_profile_doc(DeviceKind::vfc_meter))};
  emulator::TwinService service{emulator::TwinConfig{}, served};
  emulator::TwinRegisterBus bus{service};
  emulator::TwinServiceClock base{service};
  drivers::ProfileBench bench{bus, t::parse_or_throw(used), bus, served[1], bus, served[2], base};
  std::vector<std::pair<std::string, std::string>> events;
  // The supervisor's own current limit out of the way: the drive's trip is what is examined.
  SafetyLimits limits;
  limits.max_current_A = 50.0;
  SafetySupervisor sup{bench.devices(), limits,
                       [&](const std::string& k, const std::string& m) { events.emplace_back(k, m); }};
  double now = base.now_s();
  const auto run_until = [&](double end_s, auto done) {
    while (now < end_s - 1e-9) {
      now += 0.01;
      bench.clock().wait_until(now);
      sup.tick(now);
      if (done()) return;
    }
  };
  const auto never = [] { return false; };
  auto d = bench.devices();
  ASSERT_FALSE(d.load->enable(true));
  ASSERT_FALSE(d.synrm->set_angle_deg(56));
  ASSERT_FALSE(d.synrm->set_speed_rpm(700));
  ASSERT_FALSE(d.synrm->enable(true));
  run_until(now + 1.5, never);
  ASSERT_FALSE(d.load->set_torque_Nm(2.5));
  run_until(now + 1.5, never);
  ASSERT_FALSE(sup.tripped()) << sup.trip()->detail;

  // A current-sensor fault trips the SynRM drive's over-current; only the bench can take the
  // load off.
  service.locked([](emulator::Twin& tw, auto&, auto&) { tw.faults().phase_a_sensor_offset_A = 7.0; });
  const auto stopped = [&] {
    return service.locked([](emulator::Twin& tw, auto&, auto&) {
      const auto s = tw.snapshot();
      return std::fabs(s.speed_rpm) < 20.0 && std::fabs(s.load_torque_Nm) < 0.05;
    });
  };
  run_until(now + 20.0, [&] { return sup.phase() == SafetyPhase::stopped && stopped(); });

  ASSERT_TRUE(sup.tripped());
  EXPECT_EQ(sup.trip()->fault, drivers::Fault::unknown) << sup.trip()->detail;
  EXPECT_EQ(sup.trip()->fault_code_raw, 0x2310);
  EXPECT_NE(sup.trip()->detail.find("unknown fault (device code 8976)"), std::string::npos) << sup.trip()->detail;
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().first, "fault");
  EXPECT_NE(events.front().second.find("device code 8976"), std::string::npos) << events.front().second;
  EXPECT_EQ(sup.phase(), SafetyPhase::stopped);
  EXPECT_TRUE(stopped());
  drivers::SynrmTelemetry st;
  ASSERT_FALSE(d.synrm->read(st)) << d.synrm->error_detail();
  EXPECT_EQ(st.fault, drivers::Fault::unknown);
  EXPECT_EQ(st.fault_code_raw, 0x2310);
}

TEST(DecodeError, APointThatCannotReadItsDriveSaysWhereAndWhat) {
  // The drive reports running as 3 under mask 0x000B; the bench's profile has no code for it.
  json used = t::vendor_synrm(t::pulse_reset(100), json());
  used["signals"]["state"]["values"].erase("running");
  used["signals"]["state"].erase("otherwise");
  std::vector<drivers::DeviceProfile> served{
      t::parse_or_throw(t::vendor_synrm(t::pulse_reset(100), json())),
      t::parse_or_throw(t::default_profile_doc(DeviceKind::load_drive)),
      t::parse_or_throw(t::default_profile_doc(DeviceKind::vfc_meter))};
  emulator::TwinService service{emulator::TwinConfig{}, served};
  emulator::TwinRegisterBus bus{service};
  emulator::TwinServiceClock base{service};
  drivers::ProfileBench bench{bus, t::parse_or_throw(used), bus, served[1], bus, served[2], base};
  PointRequest req;
  req.speed_rpm = 500;
  req.load_Nm = 1.0;
  req.angle_deg = 56;
  const PointProcedure proc = run_point(bench.devices(), bench.clock(), req, PointOptions{});
  EXPECT_FALSE(proc.error().empty());
  EXPECT_NE(proc.error().find("reading SynRM drive telemetry"), std::string::npos) << proc.error();
  EXPECT_NE(proc.error().find("synrm_drive 'vendor SynRM drive': signal state (input 40 mask 11, unit id 1): raw "),
            std::string::npos)
      << proc.error();
  EXPECT_NE(proc.error().find("device code 3 has no label"), std::string::npos) << proc.error();
  std::printf("  %s\n", proc.error().c_str());
}

}  // namespace
}  // namespace synbench::bench
