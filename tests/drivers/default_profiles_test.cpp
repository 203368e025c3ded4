// Tests of the default profiles (synbench's own firmware) and of the docs generated from them:
// docs/register-map.md and the signal catalogue in docs/device-profile.md must match the code.
#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/devices.hpp"
#include "drivers/error.hpp"
#include "drivers/fault.hpp"
#include "drivers/modes.hpp"
#include "drivers/profile/device_profile.hpp"
#include "drivers/profile/register_map_markdown.hpp"
#include "tests/docs/generated_section.hpp"

#ifndef SYNBENCH_DOCS_DIR
#error "SYNBENCH_DOCS_DIR must name docs/ (set by tests/drivers/CMakeLists.txt)"
#endif

namespace synbench::drivers {
namespace {

std::string describe(const std::vector<ProfileError>& errors) {
  std::string s;
  for (const ProfileError& e : errors) s += "\n  '" + e.pointer + "': " + e.reason;
  return s;
}

DeviceProfile load_default(DeviceKind kind) {
  ProfileParseResult r = load_device_profile(default_profile_path(kind));
  EXPECT_TRUE(r.profile) << default_profile_path(kind) << describe(r.errors);
  return r.profile.value_or(DeviceProfile{});
}

std::vector<DeviceProfile> all_defaults() {
  std::vector<DeviceProfile> out;
  for (const DeviceKind k : kDeviceKinds) out.push_back(load_default(k));
  return out;
}

using test::read_text_file;
using test::regenerate_docs;

TEST(DefaultProfiles, EachParsesAsItsKindWithEveryCatalogueSignal) {
  for (const DeviceKind kind : kDeviceKinds) {
    const DeviceProfile p = load_default(kind);
    EXPECT_EQ(p.kind, kind);
    // The firmware implements the whole catalogue, optional signals included, but for the signals
    // of the meter kinds other than its gate (the emulator serves those through test profiles).
    std::size_t others = 0;
    for (const SignalSpec& spec : signal_catalogue(kind)) {
      const bool other_meter = kind == DeviceKind::vfc_meter &&
                               (spec.name.starts_with("total") || spec.name == "time_base_ticks" ||
                                spec.name.starts_with("pdc"));
      others += other_meter ? 1 : 0;
      if (other_meter)
        EXPECT_EQ(p.find(spec.name), nullptr) << name(kind) << " maps " << spec.name;
      else
        EXPECT_NE(p.find(spec.name), nullptr) << name(kind) << " lacks " << spec.name;
    }
    EXPECT_EQ(p.signals.size(), signal_catalogue(kind).size() - others);
  }
}

TEST(DefaultProfiles, DevicesHaveDistinctUnitIds) {
  const auto p = all_defaults();
  EXPECT_EQ(p[0].unit_id, 1);
  EXPECT_EQ(p[1].unit_id, 2);
  EXPECT_EQ(p[2].unit_id, 3);
}

TEST(DefaultProfiles, SynrmDriveMap) {
  const DeviceProfile p = load_default(DeviceKind::synrm_drive);
  const ProfileSignal* speed = p.find("speed_setpoint_rpm");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(speed->kind, RegisterKind::holding);
  EXPECT_EQ(speed->address, 16);
  EXPECT_EQ(speed->encoding.type, ValueType::f32);
  std::uint16_t words[2] = {};
  ASSERT_FALSE(encode_registers(speed->encoding, 1500, words));
  EXPECT_EQ(words[0], 0x44BB);
  EXPECT_EQ(words[1], 0x8000);
  EXPECT_EQ(encode_registers(speed->encoding, 3000.5, words), errc::invalid_argument);

  const ProfileSignal* angle = p.find("angle_setpoint_deg");
  ASSERT_NE(angle, nullptr);
  ASSERT_FALSE(encode_registers(angle->encoding, -45.5, words));
  EXPECT_EQ(words[0], 0xEE3A);  // -4550 in hundredths

  const ProfileSignal* temp = p.find("temp_C");
  ASSERT_NE(temp, nullptr);
  double temp_C = 0;
  ASSERT_FALSE(decode_registers(temp->encoding, std::vector<std::uint16_t>{750}, temp_C));
  EXPECT_NEAR(temp_C, 25.0, 1e-9);  // 750 * 0.1 - 50

  const ProfileSignal* heartbeat = p.find("heartbeat");
  ASSERT_NE(heartbeat, nullptr);
  ASSERT_TRUE(heartbeat->heartbeat);
  EXPECT_EQ(heartbeat->heartbeat->period_ms, 100u);
  EXPECT_EQ(heartbeat->heartbeat->timeout_ms, 500u);
  EXPECT_EQ(heartbeat->role, SignalRole::heartbeat);

  EXPECT_EQ(p.find("enable")->kind, RegisterKind::coil);
  EXPECT_EQ(p.find("fault_reset")->role, SignalRole::fault_reset);
  EXPECT_EQ(p.find("window_start")->role, SignalRole::window_start);
  EXPECT_EQ(p.find("voltage_limited")->kind, RegisterKind::discrete_input);
  EXPECT_EQ(p.find("window_sequence")->role, SignalRole::window_sequence);
}

// The enumerations on the wire are the ones in drivers/: codes of fault.hpp, modes of modes.hpp.
TEST(DefaultProfiles, EnumsMatchTheCode) {
  for (const DeviceKind kind : {DeviceKind::synrm_drive, DeviceKind::load_drive}) {
    const DeviceProfile p = load_default(kind);
    const auto& faults = p.find("fault_code")->values;
    ASSERT_EQ(faults.size(), 10u);
    for (const EnumValue& v : faults)
      EXPECT_EQ(v.label, fault_name(static_cast<Fault>(v.value))) << name(kind);
    const auto& states = p.find("state")->values;
    ASSERT_EQ(states.size(), 4u);
    EXPECT_EQ(states[static_cast<int>(DriveState::faulted)].label, "faulted");
  }
  const DeviceProfile synrm = load_default(DeviceKind::synrm_drive);
  const auto& estimators = synrm.find("estimator")->values;
  ASSERT_EQ(estimators.size(), kEstimatorNames.size());
  for (const EnumValue& v : estimators) EXPECT_EQ(v.label, kEstimatorNames[static_cast<std::size_t>(v.value)]);
  const auto& pwm = synrm.find("pwm_scheme")->values;
  ASSERT_EQ(pwm.size(), kPwmNames.size());
  for (const EnumValue& v : pwm) EXPECT_EQ(v.label, kPwmNames[static_cast<std::size_t>(v.value)]);
}

// One broadcast write can open the window on every device: the start coil and the length
// register sit at the same addresses on all three.
TEST(DefaultProfiles, WindowControlSharesAddressesAcrossDevices) {
  const auto p = all_defaults();
  const std::vector<std::pair<const ProfileSignal*, const ProfileSignal*>> controls = {
      {p[0].find("window_start"), p[0].find("window_length_ms")},
      {p[1].find("window_start"), p[1].find("window_length_ms")},
      {p[2].find("gate_start"), p[2].find("gate_length_ms")}};
  for (const auto& [start, length] : controls) {
    ASSERT_NE(start, nullptr);
    ASSERT_NE(length, nullptr);
    EXPECT_EQ(start->kind, RegisterKind::coil);
    EXPECT_EQ(start->address, controls[0].first->address);
    EXPECT_EQ(length->kind, RegisterKind::holding);
    EXPECT_EQ(length->address, controls[0].second->address);
    EXPECT_EQ(length->encoding.type, ValueType::u32);
  }
}

TEST(GeneratedDocs, RegisterMapMatchesTheDefaultProfiles) {
  const std::string path = std::string(SYNBENCH_DOCS_DIR) + "/register-map.md";
  const std::string generated = render_register_map(all_defaults());
  if (regenerate_docs()) std::ofstream(path) << generated;
  EXPECT_EQ(read_text_file(path), generated)
      << path << " is stale; rerun this test with SYNBENCH_REGENERATE_DOCS=1 to rewrite it";
}

TEST(GeneratedDocs, DeviceProfileDocHasTheCurrentSignalCatalogue) {
  test::expect_generated_section(std::string(SYNBENCH_DOCS_DIR) + "/device-profile.md",
                                 "<!-- signal catalogue: generated by render_signal_catalogue(), do not edit -->\n",
                                 "<!-- end of signal catalogue -->", "\n" + render_signal_catalogue());
}

TEST(GeneratedDocs, DeviceProfileDocExampleIsValid) {
  const std::string doc = read_text_file(std::string(SYNBENCH_DOCS_DIR) + "/device-profile.md");
  const std::string fence = "```json\n";
  const auto b = doc.find(fence);
  ASSERT_NE(b, std::string::npos);
  const auto e = doc.find("```", b + fence.size());
  ASSERT_NE(e, std::string::npos);
  const ProfileParseResult r =
      parse_device_profile(synbench::Json::parse(doc.substr(b + fence.size(), e - b - fence.size())));
  ASSERT_TRUE(r.profile) << describe(r.errors);
  EXPECT_EQ(r.profile->kind, DeviceKind::synrm_drive);
  EXPECT_EQ(r.profile->find("udc_V")->unit_id, 6);
  EXPECT_EQ(r.profile->find("speed_rpm")->encoding.word_order, WordOrder::little);
}

TEST(GeneratedDocs, RegisterMapShowsTheEncodings) {
  const std::string md = render_register_map(all_defaults());
  EXPECT_NE(md.find("| `speed_setpoint_rpm` | 1 | holding | 16-17 | f32 | ABCD | 1 / 0 | rpm | rw | -3000 .. 3000 | "
                    "command | — |"),
            std::string::npos);
  EXPECT_NE(md.find("| `temp_C` | 1 | input | 31 | u16 | AB | 0.1 / -50 | C | r | -50 .. 250 | telemetry | — |"),
            std::string::npos);
  EXPECT_NE(md.find("| `pwm_scheme` | 1 | holding | 19 | u16 | AB | 1 / 0 | — | rw | 0 .. 1 | command | "
                    "0 capwm, 1 aspwm |"),
            std::string::npos);
  EXPECT_NE(md.find("write every 100 ms; trips after 500 ms unchanged"), std::string::npos);
  // An array signal: its whole span of addresses and its count.
  EXPECT_NE(md.find("| `window_batch_im_A` | 1 | input | 144-163 | f32 x 10 | ABCD | 1 / 0 | A | r | -100 .. 100 | "
                    "window_result | — |"),
            std::string::npos);
}

}  // namespace
}  // namespace synbench::drivers
