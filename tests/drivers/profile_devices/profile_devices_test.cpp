// Tests of the profile devices on an in-memory bus: read planning, decoding with limits and
// enumerations, refused writes, the heartbeat, and the window protocol's sequence checks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drivers/error.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"
#include "tests/drivers/profile_devices/fake_bus.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

using testing::FakeBus;

DeviceProfile load_default(DeviceKind kind) {
  ProfileParseResult r = load_device_profile(default_profile_path(kind));
  if (!r.profile) throw std::runtime_error("default profile does not parse");
  return *r.profile;
}

class ManualClock final : public Clock {
 public:
  double now_s() const override { return t; }
  void wait_until(double t_s) override { t = std::max(t, t_s); }
  double t = 0;
};

TEST(ReadPlan, AdjacentSignalsShareARequest) {
  const DeviceProfile p = load_default(DeviceKind::synrm_drive);
  // state, fault_code: input 0-1; speed..temp: input 16-31; voltage_limited: discrete input 0.
  ReadPlan plan(p, {"state", "fault_code", "speed_rpm", "im_A", "id_A", "iq_A", "ud_V", "uq_V", "udc_V",
                    "pac_W", "temp_C", "voltage_limited"});
  EXPECT_EQ(plan.requests(), 3u);
  ReadPlan gap(p, {"window_fault_code", "window_s"});  // 104 and 106-107: a gap between
  EXPECT_EQ(gap.requests(), 2u);
  ReadPlan missing(p, {"state", "no_such_signal"});
  EXPECT_TRUE(missing.present(0));
  EXPECT_FALSE(missing.present(1));
}

TEST(ProfileSynrmDrive, ReadsTelemetryInThreeRequests) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, load_default(DeviceKind::synrm_drive));
  const DeviceProfile& p = drive.profile();
  bus.set(*p.find("state"), 1);
  bus.set(*p.find("fault_code"), 0);
  bus.set(*p.find("speed_rpm"), 700.25);
  bus.set(*p.find("udc_V"), 424.5);
  bus.set(*p.find("temp_C"), 50.0);
  bus.set(*p.find("voltage_limited"), 1);
  SynrmTelemetry t;
  ASSERT_FALSE(drive.read(t));
  EXPECT_EQ(bus.log.size(), 3u);
  EXPECT_EQ(t.state, DriveState::running);
  EXPECT_DOUBLE_EQ(t.speed_rpm, 700.25);
  EXPECT_NEAR(t.udc_V, 424.5, 1e-9);
  ASSERT_TRUE(t.temp_C);
  EXPECT_NEAR(*t.temp_C, 50.0, 1e-9);
  EXPECT_TRUE(t.voltage_limited);
}

TEST(ProfileSynrmDrive, AValueOutsideItsLimitsIsAnErrorNotData) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, load_default(DeviceKind::synrm_drive));
  bus.set(*drive.profile().find("state"), 7);  // limits 0..3
  SynrmTelemetry t;
  t.speed_rpm = 123;
  EXPECT_EQ(drive.read(t), errc::protocol);
  EXPECT_EQ(t.speed_rpm, 123);  // untouched
  bus.set(*drive.profile().find("state"), 1);
  bus.at(1, RegisterKind::input, 16) = 0x7FC0;  // f32 NaN
  bus.at(1, RegisterKind::input, 17) = 0x0000;
  EXPECT_EQ(drive.read(t), errc::protocol);
}

TEST(ProfileSynrmDrive, DeviceCodesAreTranslated) {
  DeviceProfile p = load_default(DeviceKind::synrm_drive);
  ProfileSignal& state = const_cast<ProfileSignal&>(*p.find("state"));
  state.encoding.max = 15;
  state.values = {{0, "disabled"}, {4, "running"}, {5, "stopping"}, {15, "faulted"}};
  FakeBus bus;
  ProfileSynrmDrive drive(bus, p);
  bus.set(*drive.profile().find("state"), 4);
  SynrmTelemetry t;
  ASSERT_FALSE(drive.read(t));
  EXPECT_EQ(t.state, DriveState::running);
  bus.set(*drive.profile().find("state"), 1);  // not one of this drive's numbers
  EXPECT_EQ(drive.read(t), errc::protocol);
}

TEST(ProfileSynrmDrive, WritesOutsideTheLimitsNeverReachTheWire) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, load_default(DeviceKind::synrm_drive));
  EXPECT_EQ(drive.set_speed_rpm(4000), errc::invalid_argument);
  EXPECT_EQ(drive.set_angle_deg(std::nan("")), errc::invalid_argument);
  EXPECT_TRUE(bus.log.empty());
  EXPECT_FALSE(drive.set_angle_deg(52.5));
  EXPECT_EQ(bus.at(1, RegisterKind::holding, 18), 5250);
}

TEST(ProfileSynrmDrive, ModesAbsentFromTheProfileAcceptOnlyTheDefault) {
  DeviceProfile p = load_default(DeviceKind::synrm_drive);
  std::erase_if(p.signals, [](const ProfileSignal& s) { return s.name == "estimator" || s.name == "pwm_scheme"; });
  FakeBus bus;
  ProfileSynrmDrive drive(bus, p);
  EXPECT_FALSE(drive.set_estimator(Estimator::encoder));
  EXPECT_FALSE(drive.set_pwm(Pwm::capwm));
  EXPECT_EQ(drive.set_estimator(Estimator::hfi), errc::not_supported);
  EXPECT_EQ(drive.set_pwm(Pwm::aspwm), errc::not_supported);
}

TEST(Heartbeat, NewValueEveryPeriodAndRetriedSoonAfterAFailure) {
  FakeBus bus;
  ProfileLoadDrive drive(bus, load_default(DeviceKind::load_drive));
  drive.tick(0.0);
  EXPECT_EQ(bus.at(2, RegisterKind::holding, 0), 1);
  drive.tick(0.05);  // not due: period 100 ms
  EXPECT_EQ(bus.log.size(), 1u);
  drive.tick(0.1);
  EXPECT_EQ(bus.at(2, RegisterKind::holding, 0), 2);
  bus.fail_next = make_error_code(errc::timeout);
  EXPECT_EQ(drive.tick(0.2), errc::timeout);
  EXPECT_DOUBLE_EQ(drive.next_heartbeat_s(), 0.225);
  EXPECT_FALSE(drive.tick(0.225));
  EXPECT_EQ(bus.at(2, RegisterKind::holding, 0), 3);
  EXPECT_EQ(drive.heartbeat_failures(), 1u);
}

struct WindowFixture : ::testing::Test {
  FakeBus bus;
  ManualClock clock;
  ProfileBench bench{bus, load_default(DeviceKind::synrm_drive), bus, load_default(DeviceKind::load_drive),
                     bus, load_default(DeviceKind::vfc_meter), clock};
  // Status and sequence of every device (input 100, 101 at units 1..3).
  void set_window(std::uint16_t status, std::uint16_t sequence) {
    for (std::uint8_t u = 1; u <= 3; ++u) {
      bus.at(u, RegisterKind::input, 100) = status;
      bus.at(u, RegisterKind::input, 101) = sequence;
    }
  }
};

TEST_F(WindowFixture, LengthsFirstThenTheStartCoilsBackToBack) {
  set_window(2, 5);
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  std::vector<std::string> writes;
  for (const auto& r : bus.log)
    if (r.op == "write") writes.push_back(std::to_string(r.unit_id) + (r.kind == RegisterKind::coil ? "c" : "h") + std::to_string(r.address));
  EXPECT_EQ(writes, (std::vector<std::string>{"1h2", "2h2", "3h2", "1c2", "2c2", "3c2"}));
  EXPECT_EQ(bus.at(1, RegisterKind::holding, 3), 1000);  // u32 ms, low word
}

TEST_F(WindowFixture, ResultsOfAnEarlierWindowAreNeverTaken) {
  SynrmWindow w;
  EXPECT_EQ(bench.synrm().read_window(w), errc::not_ready);  // no window started by this bench
  set_window(2, 5);  // an earlier window's results are on the device
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  EXPECT_FALSE(bench.trigger().window_closed());
  EXPECT_EQ(bench.synrm().read_window(w), errc::not_ready);  // done, but still sequence 5
  set_window(1, 5);
  EXPECT_FALSE(bench.trigger().window_closed());
  const DeviceProfile& p = bench.synrm().profile();
  bus.set(*p.find("window_samples"), 10000);
  bus.set(*p.find("window_s"), 1.0);
  bus.set(*p.find("window_im_A"), 1.905);
  set_window(2, 6);
  EXPECT_TRUE(bench.trigger().window_closed());
  ASSERT_FALSE(bench.synrm().read_window(w));
  EXPECT_EQ(w.samples, 10000u);
  EXPECT_NEAR(w.im_A, 1.905, 1e-6);
  EXPECT_FALSE(w.pos_err_mean_deg);  // encoder: estimator results not read
}

TEST_F(WindowFixture, ASequenceMovingDuringTheReadIsNotReady) {
  set_window(2, 5);
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  set_window(2, 6);
  ASSERT_TRUE(bench.trigger().window_closed());
  // Another window closes between the results and the check of the sequence.
  bus.before = [&](const FakeBus::Request& r) {
    if (r.unit_id == 2 && r.address == 100 && r.count == 2) set_window(2, 7);
  };
  LoadWindow lw;
  EXPECT_EQ(bench.load().read_window(lw), errc::not_ready);
}

TEST_F(WindowFixture, AWindowThatNeverClosesReadsAsTimeout) {
  set_window(2, 5);
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  set_window(1, 5);
  clock.t = 1.0 + 5.0 + 0.1;  // past the window and its margin
  EXPECT_TRUE(bench.trigger().window_closed());
  MeterReading m;
  EXPECT_EQ(bench.meter().read(m), errc::timeout);
}

TEST_F(WindowFixture, AnOpenWindowIsBusy) {
  set_window(1, 5);
  EXPECT_EQ(bench.trigger().open_window(1.0), errc::busy);
}

TEST_F(WindowFixture, ALostReplyOrATransientExceptionIsRepeatedARefusalNever) {
  bus.at(1, RegisterKind::input, 0) = 1;  // running
  bus.fail_next = make_error_code(errc::timeout);
  SynrmTelemetry t;
  ASSERT_FALSE(bench.synrm().read(t));
  EXPECT_EQ(t.state, DriveState::running);
  EXPECT_EQ(bus.log.size(), 4u);  // three requests, the first one twice
  // Exception 6, server device busy: not now, so again.
  bus.log.clear();
  bus.fail_next = make_error_code(errc::exception_reply);
  bus.exception_code = 6;
  ASSERT_FALSE(bench.synrm().read(t));
  EXPECT_EQ(bus.log.size(), 4u);
  // Exception 2, illegal data address: the same request gets the same answer.
  bus.log.clear();
  bus.fail_next = make_error_code(errc::exception_reply);
  bus.exception_code = 2;
  EXPECT_EQ(bench.synrm().read(t), errc::exception_reply);
  EXPECT_EQ(bus.log.size(), 1u);
}

TEST_F(WindowFixture, RepeatsStopAtTheRetryBudgetOrTheCount) {
  // Every request fails after 0.1 s of bench time: repeats start only within the 0.25 s budget.
  bus.before = [&](const FakeBus::Request&) {
    clock.t += 0.1;
    bus.fail_next = make_error_code(errc::timeout);
  };
  SynrmTelemetry t;
  EXPECT_EQ(bench.synrm().read(t), errc::timeout);
  EXPECT_EQ(bus.log.size(), 3u);  // at 0, 0.1 and 0.2 s; none at 0.3 s
  // Failures that take no time: the count (3 repeats) bounds them.
  bus.log.clear();
  bus.before = [&](const FakeBus::Request&) { bus.fail_next = make_error_code(errc::protocol); };
  EXPECT_EQ(bench.synrm().read(t), errc::protocol);
  EXPECT_EQ(bus.log.size(), 4u);
}

int starts_on(const FakeBus& bus, std::uint8_t unit) {
  int n = 0;
  for (const auto& r : bus.log) n += r.op == "write" && r.kind == RegisterKind::coil && r.address == 2 && r.unit_id == unit;
  return n;
}

TEST_F(WindowFixture, AStartWhoseReplyWasLostIsReadBackNotRepeated) {
  set_window(2, 5);
  // The drive executes the start (its window opens) but the reply is lost.
  bool lost = false;
  bus.before = [&](const FakeBus::Request& r) {
    if (r.op == "write" && r.kind == RegisterKind::coil && r.address == 2 && r.unit_id == 1 && !lost) {
      lost = true;
      bus.at(1, RegisterKind::input, 100) = 1;
      bus.fail_next = make_error_code(errc::timeout);
    }
  };
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  EXPECT_EQ(starts_on(bus, 1), 1);  // a second start would open a second window (or be busy)
  EXPECT_EQ(bench.synrm().window().starts_confirmed(), 1u);
  EXPECT_EQ(starts_on(bus, 2), 1);
  EXPECT_EQ(starts_on(bus, 3), 1);
}

TEST_F(WindowFixture, AStartThatWasNotExecutedIsWrittenAgain) {
  set_window(2, 5);
  // Refused before execution (exception 4, as `synbench emulate` injects): status and sequence
  // unchanged, so the start is written again.
  bool refused = false;
  bus.before = [&](const FakeBus::Request& r) {
    if (r.op == "write" && r.kind == RegisterKind::coil && r.address == 2 && r.unit_id == 1 && !refused) {
      refused = true;
      bus.exception_code = 4;
      bus.fail_next = make_error_code(errc::exception_reply);
    }
  };
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  EXPECT_EQ(starts_on(bus, 1), 2);
  EXPECT_EQ(bench.synrm().window().start_repeats(), 1u);
}

TEST_F(WindowFixture, AStartRefusedForGoodIsNotRepeated) {
  set_window(2, 5);
  bus.before = [&](const FakeBus::Request& r) {
    if (r.op == "write" && r.kind == RegisterKind::coil && r.address == 2 && r.unit_id == 1) {
      bus.exception_code = 3;
      bus.fail_next = make_error_code(errc::exception_reply);
    }
  };
  EXPECT_EQ(bench.trigger().open_window(1.0), errc::exception_reply);
  EXPECT_EQ(starts_on(bus, 1), 1);
}

TEST_F(WindowFixture, TheClockSendsHeartbeatsWhileTheBenchWaits) {
  bench.clock().wait_until(1.0);
  // 0, 0.1, ..., 1.0: ten or eleven heartbeats to each drive (the last one falls within
  // rounding of the end), none to the meter (it has none).
  int drive1 = 0, drive2 = 0, meter = 0;
  for (const auto& r : bus.log) {
    if (r.op != "write") continue;
    (r.unit_id == 1 ? drive1 : r.unit_id == 2 ? drive2 : meter)++;
  }
  EXPECT_GE(drive1, 10);
  EXPECT_LE(drive1, 11);
  EXPECT_EQ(drive2, drive1);
  EXPECT_EQ(meter, 0);
}

// --- Decode errors, bits, unknown faults, reset pulses, any-write refresh ---------------------

TEST(ProfileSynrmDrive, DecodeErrorsNameDeviceSignalRegisterAndRawWords) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, load_default(DeviceKind::synrm_drive));
  bus.set(*drive.profile().find("state"), 7);  // limits 0..3
  SynrmTelemetry t;
  EXPECT_EQ(drive.read(t), errc::protocol);
  EXPECT_EQ(drive.error_detail(),
            "synrm_drive 'synbench SynRM drive': signal state (input 0, unit id 1): raw 0x0007: 7 is outside the "
            "profile's limits [0, 3] (u16, scale 1, offset 0)");
  bus.set(*drive.profile().find("state"), 1);
  bus.at(1, RegisterKind::input, 16) = 0x7FC0;  // f32 NaN
  bus.at(1, RegisterKind::input, 17) = 0x0000;
  EXPECT_EQ(drive.read(t), errc::protocol);
  EXPECT_NE(drive.error_detail().find("signal speed_rpm (input 16..17, unit id 1): raw 0x7FC0 0x0000"), std::string::npos)
      << drive.error_detail();
  bus.at(1, RegisterKind::input, 16) = 0;
  ASSERT_FALSE(drive.read(t));
  EXPECT_EQ(drive.error_detail(), "");  // a success clears it
  bus.fail_next = make_error_code(errc::timeout);
  EXPECT_EQ(drive.read(t), errc::timeout);
  EXPECT_NE(drive.error_detail().find("reading discrete_input 0..1, unit id 1"), std::string::npos) << drive.error_detail();
}

TEST(ProfileSynrmDrive, StateFromStatusBitsAndFaultsWithoutALabel) {
  FakeBus bus;
  ProfileSynrmDrive drive(
      bus, synbench::testing::parse_or_throw(synbench::testing::vendor_synrm(synbench::testing::pulse_reset(),
                                                                              json(), /*watchdog_code=*/false)));
  SynrmTelemetry t;
  bus.at(1, RegisterKind::input, 40) = 0xFFF3;  // bits 0, 1 of mask 0x000B: 3, running; the rest ignored
  ASSERT_FALSE(drive.read(t)) << drive.error_detail();
  EXPECT_EQ(t.state, DriveState::running);
  EXPECT_EQ(t.fault, Fault::none);
  EXPECT_FALSE(t.fault_code_raw);
  bus.at(1, RegisterKind::input, 40) = 0x0009;  // 9: faulted
  bus.at(1, RegisterKind::input, 41) = 0x2311;  // the second code of overcurrent
  ASSERT_FALSE(drive.read(t));
  EXPECT_EQ(t.state, DriveState::faulted);
  EXPECT_EQ(t.fault, Fault::overcurrent);
  bus.at(1, RegisterKind::input, 41) = 0x8130;  // the watchdog, which this profile does not list
  ASSERT_FALSE(drive.read(t)) << drive.error_detail();
  EXPECT_EQ(t.fault, Fault::unknown);
  EXPECT_EQ(t.fault_code_raw, 0x8130);
  // The default profile's fault code is limited to 0..9; a 12 is a fault all the same.
  FakeBus own_bus;
  ProfileSynrmDrive own(own_bus, load_default(DeviceKind::synrm_drive));
  own_bus.set(*own.profile().find("fault_code"), 12);
  ASSERT_FALSE(own.read(t)) << own.error_detail();
  EXPECT_EQ(t.fault, Fault::unknown);
  EXPECT_EQ(t.fault_code_raw, 12);
}

TEST(ProfileSynrmDrive, AStateCodeWithoutALabelIsAnErrorThatSaysSo) {
  json doc = synbench::testing::vendor_synrm(synbench::testing::pulse_reset(), json());
  doc["signals"]["state"].erase("otherwise");
  doc["signals"]["state"]["values"].erase("stopping");
  FakeBus bus;
  ProfileSynrmDrive drive(bus, synbench::testing::parse_or_throw(doc));
  bus.at(1, RegisterKind::input, 40) = 0x0006;  // bit 2 is not the state's: 2 under mask 0x000B
  SynrmTelemetry t;
  EXPECT_EQ(drive.read(t), errc::protocol);
  EXPECT_EQ(drive.error_detail(),
            "synrm_drive 'vendor SynRM drive': signal state (input 40 mask 11, unit id 1): raw 0x0006: device code 2 "
            "has no label and no \"otherwise\"");
}

TEST(ProfileSynrmDrive, APulseResetIsClearedFromTheTickAndKeepsTheOtherBits) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, synbench::testing::parse_or_throw(synbench::testing::vendor_synrm(
                                   synbench::testing::pulse_reset(100), synbench::testing::no_watchdog())));
  ASSERT_FALSE(drive.io().write("enable", 1));
  bus.at(1, RegisterKind::holding, 40) |= 0x0100;  // a bit the profile does not map stays as the device has it
  EXPECT_EQ(drive.next_heartbeat_s(), std::numeric_limits<double>::infinity());
  ASSERT_FALSE(drive.reset_fault());
  EXPECT_EQ(bus.at(1, RegisterKind::holding, 40), 0x0181);
  ASSERT_FALSE(drive.tick(10.0));  // the hold starts at the first tick
  EXPECT_DOUBLE_EQ(drive.next_heartbeat_s(), 10.1);
  ASSERT_FALSE(drive.tick(10.05));
  EXPECT_EQ(bus.at(1, RegisterKind::holding, 40), 0x0181);
  ASSERT_FALSE(drive.tick(10.1));
  EXPECT_EQ(bus.at(1, RegisterKind::holding, 40), 0x0101);
  EXPECT_EQ(drive.next_heartbeat_s(), std::numeric_limits<double>::infinity());
  // A level reset writes 1 and nothing after.
  FakeBus level_bus;
  ProfileSynrmDrive level(level_bus, synbench::testing::parse_or_throw(synbench::testing::vendor_synrm(
                                         synbench::testing::level_reset(), synbench::testing::no_watchdog())));
  ASSERT_FALSE(level.reset_fault());
  ASSERT_FALSE(level.tick(20.0));
  ASSERT_FALSE(level.tick(30.0));
  EXPECT_EQ(level_bus.at(1, RegisterKind::holding, 40), 0x0080);
}

TEST(Heartbeat, AnAnyWriteWatchdogRewritesTheLastValueOnceThereIsOne) {
  FakeBus bus;
  ProfileSynrmDrive drive(bus, synbench::testing::parse_or_throw(synbench::testing::vendor_synrm(
                                   synbench::testing::pulse_reset(), synbench::testing::any_write("speed_setpoint_rpm", 250, 1000))));
  ASSERT_FALSE(drive.tick(0.0));
  EXPECT_TRUE(bus.log.empty()) << "nothing to refresh before the first write";
  ASSERT_FALSE(drive.set_speed_rpm(700));
  bus.log.clear();
  bus.at(1, RegisterKind::holding, 16) = 0;  // so the rewrite shows
  ASSERT_FALSE(drive.tick(0.3));
  ASSERT_EQ(bus.log.size(), 1u);
  EXPECT_EQ(bus.log[0].op, "write");
  EXPECT_EQ(bus.log[0].address, 16);
  double v = 0;
  const std::uint16_t w[2] = {bus.at(1, RegisterKind::holding, 16), bus.at(1, RegisterKind::holding, 17)};
  ASSERT_FALSE(decode_registers(drive.profile().find("speed_setpoint_rpm")->encoding, w, v));
  EXPECT_EQ(v, 700);
  EXPECT_DOUBLE_EQ(drive.next_heartbeat_s(), 0.55);
  ASSERT_FALSE(drive.tick(0.5));
  EXPECT_EQ(bus.log.size(), 1u);
  ASSERT_FALSE(drive.tick(0.55));
  EXPECT_EQ(bus.log.size(), 2u);
}

}  // namespace
}  // namespace synbench::drivers
