// Tests of bits and masks, several codes per label, "otherwise", the reset mode and the
// watchdog kinds of a device profile: codec vectors computed by hand, and each mistake refused
// at its JSON pointer.
#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cmath>

#include "drivers/error.hpp"
#include "drivers/fault.hpp"
#include "drivers/profile/device_profile.hpp"
#include "drivers/profile/register_codec.hpp"
#include "drivers/profile/signal_codes.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;
using testing::vendor_synrm;

std::string describe(const std::vector<ProfileError>& errors) {
  std::string s;
  for (const ProfileError& e : errors) s += "\n  '" + e.pointer + "': " + e.reason;
  return s;
}

// Exactly one error, at `path`, saying `reason`.
void expect_refused(const json& doc, const std::string& path, const std::string& reason) {
  const auto r = parse_device_profile(doc);
  ASSERT_FALSE(r.profile);
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].pointer, path) << describe(r.errors);
  EXPECT_NE(r.errors[0].reason.find(reason), std::string::npos) << describe(r.errors);
}

RegisterEncoding u16() { return RegisterEncoding{}; }

TEST(RegisterField, DecodesTheMaskedBitsShiftedDown) {
  double v = -1;
  ASSERT_FALSE(decode_field(u16(), 0x000B, 0xFFFB, v));  // bits 0, 1, 3 set; bit 2 clear
  EXPECT_EQ(v, 11);
  ASSERT_FALSE(decode_field(u16(), 0x000B, 0x0008, v));
  EXPECT_EQ(v, 8);
  ASSERT_FALSE(decode_field(u16(), 0x0080, 0x0081, v));  // bit 7
  EXPECT_EQ(v, 1);
  ASSERT_FALSE(decode_field(u16(), 0x0F00, 0x0A55, v));
  EXPECT_EQ(v, 0xA);
  // The word's byte order is undone before the mask applies.
  RegisterEncoding little = u16();
  little.byte_order = ByteOrder::little;
  ASSERT_FALSE(decode_field(little, 0x0100, 0x0001, v));
  EXPECT_EQ(v, 1);
  // Scale and offset apply to the field.
  RegisterEncoding scaled = u16();
  scaled.scale = 0.5;
  scaled.offset = 1;
  ASSERT_FALSE(decode_field(scaled, 0x00F0, 0x0030, v));
  EXPECT_EQ(v, 2.5);
  EXPECT_EQ(field_max(0x000B), 11);
  EXPECT_EQ(field_max(0x0F00), 15);
}

TEST(RegisterField, EncodingKeepsTheOtherBits) {
  std::uint16_t w = 0xA5A5;
  ASSERT_FALSE(encode_field(u16(), 0x0080, 0, w));
  EXPECT_EQ(w, 0xA525);
  ASSERT_FALSE(encode_field(u16(), 0x0080, 1, w));
  EXPECT_EQ(w, 0xA5A5);
  ASSERT_FALSE(encode_field(u16(), 0x0F00, 3, w));
  EXPECT_EQ(w, 0xA3A5);
  RegisterEncoding little = u16();
  little.byte_order = ByteOrder::little;
  std::uint16_t l = 0x0000;
  ASSERT_FALSE(encode_field(little, 0x0100, 1, l));
  EXPECT_EQ(l, 0x0001);
  // What does not fit the bits is refused and leaves the word alone.
  std::uint16_t x = 0x1234;
  EXPECT_EQ(encode_field(u16(), 0x0080, 2, x), errc::invalid_argument);
  EXPECT_EQ(encode_field(u16(), 0x0F00, 16, x), errc::invalid_argument);
  EXPECT_EQ(x, 0x1234);
  RegisterEncoding f32 = u16();
  f32.type = ValueType::f32;
  EXPECT_EQ(encode_field(f32, 0x0001, 1, x), errc::invalid_argument);
  EXPECT_EQ(encode_field(u16(), 0, 1, x), errc::invalid_argument);
}

TEST(ProfileBits, AControlAndAStatusWordShareTheirRegistersOnDisjointBits) {
  const auto r = parse_device_profile(vendor_synrm(testing::pulse_reset(100), testing::any_write("speed_setpoint_rpm")));
  ASSERT_TRUE(r.profile) << describe(r.errors);
  const DeviceProfile& p = *r.profile;
  EXPECT_EQ(p.find("enable")->mask, 0x0001);
  EXPECT_EQ(p.find("pwm_scheme")->mask, 0x0010);
  EXPECT_EQ(p.find("fault_reset")->mask, 0x0080);
  EXPECT_EQ(p.find("state")->mask, 0x000B);
  EXPECT_EQ(p.find("fault_reset")->reset.mode, FaultResetMode::Mode::pulse);
  EXPECT_EQ(p.find("fault_reset")->reset.pulse_ms, 100u);
  // A masked command needs no min and max: its bits bound it.
  EXPECT_TRUE(std::isinf(p.find("enable")->encoding.max));
  EXPECT_EQ(p.watchdog.kind, WatchdogKind::any_write);
  EXPECT_EQ(p.watchdog.refresh, "speed_setpoint_rpm");
  EXPECT_EQ(p.watchdog.period_ms, 250u);
  EXPECT_EQ(p.watchdog.timeout_ms, 1000u);
  EXPECT_EQ(p.find("heartbeat"), nullptr);
}

TEST(ProfileBits, SeveralCodesPerLabelAndOtherwise) {
  // The example of docs/device-profile.md: state from the status word's bits 0, 1 and 3.
  json doc = vendor_synrm(testing::level_reset(), json());
  doc["signals"]["state"]["values"] = {{"running", {3}}, {"faulted", {8, 9, 10, 11}}, {"disabled", {0, 1}}};
  doc["signals"]["state"]["otherwise"] = "stopping";
  const auto r = parse_device_profile(doc);
  ASSERT_TRUE(r.profile) << describe(r.errors);
  const ProfileSignal& state = *r.profile->find("state");
  const DeviceKind k = DeviceKind::synrm_drive;
  const auto bench = [&](double device) {
    double code = -1;
    EXPECT_FALSE(to_bench_code(k, state, device, code)) << device;
    return code;
  };
  EXPECT_EQ(bench(3), 1);   // running
  EXPECT_EQ(bench(0), 0);   // disabled
  EXPECT_EQ(bench(1), 0);   // disabled too
  EXPECT_EQ(bench(10), 3);  // faulted
  EXPECT_EQ(bench(2), 2);   // no label: otherwise, stopping
  EXPECT_EQ(bench(7), 2);
  // The first listed code is what the bench writes.
  double device = -1;
  ASSERT_FALSE(to_device_value(k, state, 3, device));
  EXPECT_EQ(device, 8);
  ASSERT_FALSE(to_device_value(k, state, 0, device));
  EXPECT_EQ(device, 0);
  EXPECT_EQ(to_device_value(k, state, 2, device), errc::not_supported);  // stopping has no code
}

TEST(ProfileBits, WithoutOtherwiseAnUnlistedStateIsADecodeError) {
  json doc = vendor_synrm(testing::level_reset(), json());
  doc["signals"]["state"].erase("otherwise");
  const auto r = parse_device_profile(doc);
  ASSERT_TRUE(r.profile) << describe(r.errors);
  double code = 0;
  EXPECT_EQ(to_bench_code(DeviceKind::synrm_drive, *r.profile->find("state"), 4, code), errc::protocol);
}

TEST(ProfileBits, AFaultCodeWithoutALabelIsAnUnknownFaultNeverAnError) {
  const auto r = parse_device_profile(vendor_synrm(testing::level_reset(), json(), /*watchdog_code=*/false));
  ASSERT_TRUE(r.profile) << describe(r.errors);
  const ProfileSignal& f = *r.profile->find("fault_code");
  double code = -1;
  ASSERT_FALSE(to_bench_code(DeviceKind::synrm_drive, f, 0x2311, code));
  EXPECT_EQ(static_cast<Fault>(static_cast<int>(code)), Fault::overcurrent);
  ASSERT_FALSE(to_bench_code(DeviceKind::synrm_drive, f, 0x8130, code));
  EXPECT_EQ(static_cast<Fault>(static_cast<int>(code)), Fault::unknown);
  EXPECT_EQ(describe_fault(Fault::unknown, 8721), "unknown fault (device code 8721)");
  EXPECT_EQ(describe_fault(Fault::overspeed, std::nullopt), "overspeed");
  // With the bench's own codes (no values) too.
  const auto own = parse_device_profile(testing::default_profile_doc(DeviceKind::load_drive));
  ASSERT_TRUE(own.profile);
  const ProfileSignal* wf = own.profile->find("fault_code");
  ASSERT_FALSE(to_bench_code(DeviceKind::load_drive, *wf, 42, code));
  EXPECT_EQ(static_cast<Fault>(static_cast<int>(code)), Fault::unknown);
  // A catch-all label takes precedence over unknown.
  json doc = vendor_synrm(testing::level_reset(), json(), false);
  doc["signals"]["fault_code"]["otherwise"] = "overtemperature";
  const auto o = parse_device_profile(doc);
  ASSERT_TRUE(o.profile) << describe(o.errors);
  ASSERT_FALSE(to_bench_code(DeviceKind::synrm_drive, *o.profile->find("fault_code"), 0x8130, code));
  EXPECT_EQ(static_cast<Fault>(static_cast<int>(code)), Fault::overtemperature);
}

TEST(ProfileBits, MistakesAreRefusedAtTheirPointers) {
  const json base = vendor_synrm(testing::pulse_reset(), testing::any_write("speed_setpoint_rpm"));
  auto with = [&](auto mutate) {
    json d = base;
    mutate(d);
    return d;
  };
  expect_refused(with([](json& d) { d["signals"]["pwm_scheme"]["bit"] = 0; }), "/signals/pwm_scheme/mask",
                 "shares bits 1 of holding 40 (unit id 1) with 'enable'");
  expect_refused(with([](json& d) { d["signals"]["state"]["mask"] = 0x0101; d["signals"]["fault_code"]["address"] = 40;
                                    d["signals"]["fault_code"]["mask"] = 0x0100; d["signals"]["fault_code"]["values"] = {{"none", 0}}; }),
                 "/signals/fault_code/mask", "with 'state'");
  expect_refused(with([](json& d) { d["signals"]["enable"]["mask"] = 1; }), "/signals/enable/mask", "give bit or mask, not both");
  expect_refused(with([](json& d) { d["signals"]["enable"]["bit"] = 16; }), "/signals/enable/bit", "16 is outside 0..15");
  expect_refused(with([](json& d) { d["signals"]["state"]["mask"] = 0; }), "/signals/state/mask", "0 is outside 1..65535");
  expect_refused(with([](json& d) { d["signals"]["speed_rpm"]["bit"] = 1; }), "/signals/speed_rpm/bit",
                 "applies to a u16 register only, not f32");
  expect_refused(with([](json& d) { d["signals"]["window_start"]["bit"] = 1; }), "/signals/window_start/bit",
                 "does not apply to a coil");
  // An unmasked signal on a shared register overlaps as before.
  {
    json d = base;
    d["signals"]["angle_setpoint_deg"]["address"] = 40;
    const auto r = parse_device_profile(d);
    ASSERT_FALSE(r.profile);
    // Once per masked signal of the control word.
    EXPECT_EQ(r.errors.size(), 3u) << describe(r.errors);
    // Reported at the later signal of each pair, in the document's order.
    for (const ProfileError& e : r.errors)
      EXPECT_TRUE(e.pointer == "/signals/angle_setpoint_deg/address" ||
                  e.reason.find("overlaps 'angle_setpoint_deg' (holding 40..40, unit id 1)") != std::string::npos)
          << describe(r.errors);
  }
  expect_refused(with([](json& d) { d["signals"]["state"]["values"]["running"] = {3, 8}; }),
                 "/signals/state/values/faulted/0", "8 is also a code of 'running'");
  expect_refused(with([](json& d) { d["signals"]["state"]["values"]["running"] = {3, 16}; }),
                 "/signals/state/values/running/1", "16 is outside the signal's limits, type or bits");
  expect_refused(with([](json& d) { d["signals"]["state"]["values"]["running"] = json::array(); }),
                 "/signals/state/values/running", "at least one code");
  expect_refused(with([](json& d) { d["signals"]["state"]["values"]["running"] = {"3"}; }),
                 "/signals/state/values/running/0", "must be an integer or an array of integers");
  expect_refused(with([](json& d) { d["signals"]["state"]["otherwise"] = "broken"; }), "/signals/state/otherwise",
                 "unknown label 'broken' for state");
  expect_refused(with([](json& d) { d["signals"]["speed_rpm"]["otherwise"] = "running"; }),
                 "/signals/speed_rpm/otherwise", "not an enumerated signal");
  expect_refused(with([](json& d) { d["signals"]["fault_reset"]["reset"] = {{"mode", "edge"}}; }),
                 "/signals/fault_reset/reset/mode", "unknown reset mode 'edge' (expected level, pulse)");
  expect_refused(with([](json& d) { d["signals"]["fault_reset"]["reset"] = {{"mode", "pulse"}}; }),
                 "/signals/fault_reset/reset/pulse_ms", "required");
  expect_refused(with([](json& d) { d["signals"]["fault_reset"]["reset"] = {{"mode", "level"}, {"pulse_ms", 5}}; }),
                 "/signals/fault_reset/reset/pulse_ms", "applies to mode pulse only");
  expect_refused(with([](json& d) { d["signals"]["enable"]["reset"] = {{"mode", "level"}}; }), "/signals/enable/reset",
                 "applies to the fault_reset signal only");
}

TEST(ProfileWatchdog, KindsAndTheirMistakes) {
  const json base = vendor_synrm(testing::level_reset(), testing::any_write("speed_setpoint_rpm"));
  auto with = [&](auto mutate) {
    json d = base;
    mutate(d);
    return d;
  };
  // None must be said; then the profile needs no heartbeat.
  const auto none = parse_device_profile(with([](json& d) { d["watchdog"] = testing::no_watchdog(); }));
  ASSERT_TRUE(none.profile) << describe(none.errors);
  EXPECT_EQ(none.profile->watchdog.kind, WatchdogKind::none);
  expect_refused(with([](json& d) { d.erase("watchdog"); }), "/watchdog",
                 "required when the profile maps no heartbeat signal");
  // The default profiles' heartbeat is a counter, explicit or not.
  const auto counter = parse_device_profile(testing::default_profile_doc(DeviceKind::synrm_drive));
  ASSERT_TRUE(counter.profile);
  EXPECT_EQ(counter.profile->watchdog.kind, WatchdogKind::counter);
  EXPECT_EQ(counter.profile->watchdog.period_ms, 100u);
  EXPECT_EQ(counter.profile->watchdog.timeout_ms, 500u);
  json explicit_counter = testing::default_profile_doc(DeviceKind::synrm_drive);
  explicit_counter["watchdog"] = {{"kind", "counter"}};
  EXPECT_TRUE(parse_device_profile(explicit_counter).profile);
  explicit_counter["watchdog"]["timeout_ms"] = 500;
  expect_refused(explicit_counter, "/watchdog/timeout_ms", "on the heartbeat signal");
  json contradiction = testing::default_profile_doc(DeviceKind::synrm_drive);
  contradiction["watchdog"] = testing::no_watchdog();
  expect_refused(contradiction, "/watchdog/kind", "maps a heartbeat signal");
  // A meter has no watchdog unless it says so.
  const auto meter = parse_device_profile(testing::default_profile_doc(DeviceKind::vfc_meter));
  ASSERT_TRUE(meter.profile);
  EXPECT_EQ(meter.profile->watchdog.kind, WatchdogKind::none);

  expect_refused(with([](json& d) { d["watchdog"] = {{"kind", "counter"}}; }), "/watchdog/kind", "needs a heartbeat signal");
  expect_refused(with([](json& d) { d["watchdog"]["kind"] = "sometimes"; }), "/watchdog/kind",
                 "unknown watchdog kind 'sometimes' (expected counter, any_write, none)");
  expect_refused(with([](json& d) { d["watchdog"]["refresh"] = "speed_rpm"; }), "/watchdog/refresh",
                 "'speed_rpm' is not a command signal");
  expect_refused(with([](json& d) {
                   d["watchdog"]["refresh"] = "estimator";
                   d["signals"].erase("estimator");
                 }),
                 "/watchdog/refresh", "'estimator' is not mapped");
  expect_refused(with([](json& d) { d["watchdog"]["timeout_ms"] = 250; }), "/watchdog/timeout_ms",
                 "must exceed period_ms (250)");
  expect_refused(with([](json& d) { d["watchdog"].erase("period_ms"); }), "/watchdog/period_ms", "required");
  expect_refused(with([](json& d) { d["watchdog"]["every"] = 1; }), "/watchdog/every", "unknown field");
  expect_refused(with([](json& d) { d["watchdog"] = {{"kind", "none"}, {"timeout_ms", 100}}; }), "/watchdog/timeout_ms",
                 "applies to kind any_write only");
}

}  // namespace
}  // namespace synbench::drivers
