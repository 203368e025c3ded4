// Tests of what the emulator serves for a drive state its profile has no number for: the
// profile's `otherwise`, else the documented fallback (stopping -> running, faulted ->
// disabled) with a warning naming the profile and the state, else a refusal at start; and the
// register server putting that number on the wire.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "drivers/profile/signal_codes.hpp"
#include "emulator/modbus/modbus_pdu.hpp"
#include "emulator/modbus/register_server.hpp"
#include "emulator/modbus/served_codes.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using json = synbench::Json;

constexpr double kRunning = 1, kStopping = 2, kFaulted = 3;  // the bench's state codes

json vendor() {
  return synbench::testing::vendor_words(synbench::testing::default_profile_doc(DeviceKind::synrm_drive),
                                         synbench::testing::pulse_reset());
}

const drivers::ProfileSignal& state_of(const drivers::DeviceProfile& p) { return *p.find("state"); }

class StateProvider final : public SignalProvider {
 public:
  double read_signal(DeviceKind, const drivers::ProfileSignal& s) override { return s.name == "state" ? state : 0.0; }
  std::error_code write_signal(DeviceKind, const drivers::ProfileSignal&, double) override { return {}; }
  double state = 0;
};

// The status word at input 40 as the register server answers it with the twin in `state`.
std::uint16_t status_word(const drivers::DeviceProfile& p, double state) {
  StateProvider provider;
  provider.state = state;
  RegisterServer server({p}, provider);
  std::vector<std::uint8_t> pdu(5);
  pdu[0] = 0x04;
  modbus::put16(&pdu[1], 40);
  modbus::put16(&pdu[3], 1);
  std::uint8_t reply[modbus::kMaxPdu];
  const std::size_t n = server.handle(p.unit_id, pdu, reply);
  EXPECT_EQ(n, 4u);
  return static_cast<std::uint16_t>(reply[2] << 8 | reply[3]);
}

double read_back(const drivers::DeviceProfile& p, std::uint16_t word) {
  double field = static_cast<double>(word & state_of(p).mask), code = -1;
  EXPECT_FALSE(drivers::to_bench_code(p.kind, state_of(p), field, code));
  return code;
}

TEST(ServedCodes, TheDefaultAndTheVendorMapsShowEveryStateThemselves) {
  for (const json& doc : {synbench::testing::default_profile_doc(DeviceKind::synrm_drive),
                          synbench::testing::default_profile_doc(DeviceKind::load_drive), vendor()}) {
    const auto notes = check_served_codes({synbench::testing::parse_or_throw(doc)});
    EXPECT_TRUE(notes.warnings.empty()) << notes.warnings.front();
    EXPECT_TRUE(notes.errors.empty()) << notes.errors.front();
  }
}

TEST(ServedCodes, StoppingWithoutANumberIsServedAsRunningWithAWarning) {
  json doc = vendor();
  doc["signals"]["state"]["values"].erase("stopping");
  const auto p = synbench::testing::parse_or_throw(doc);
  const auto notes = check_served_codes({p});
  ASSERT_EQ(notes.warnings.size(), 1u);
  EXPECT_EQ(notes.warnings[0],
            "profile 'synbench SynRM drive' (synrm_drive): signal state has no number for 'stopping'; the emulator "
            "serves 'running' (3) in that state");
  EXPECT_TRUE(notes.errors.empty());
  // Before: 0, which this map reads as disabled while the machine still turns.
  EXPECT_EQ(status_word(p, kStopping), 0x0003);
  EXPECT_EQ(read_back(p, status_word(p, kStopping)), kRunning);
  EXPECT_EQ(status_word(p, kRunning), 0x0003);
}

TEST(ServedCodes, AStateThatIsTheProfilesOtherwiseIsServedAsANumberThatReadsAsIt) {
  // docs/device-profile.md, "Bits, several codes and catch-alls": stopping is the catch-all.
  json doc = vendor();
  doc["signals"]["state"]["values"] = {{"running", {3}}, {"faulted", {8, 9, 10, 11}}, {"disabled", {0, 1}}};
  doc["signals"]["state"]["otherwise"] = "stopping";
  const auto p = synbench::testing::parse_or_throw(doc);
  const auto notes = check_served_codes({p});
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings.front();
  EXPECT_TRUE(notes.errors.empty());
  EXPECT_EQ(status_word(p, kStopping), 0x0002);  // the smallest number under mask 0x000B no label lists
  EXPECT_EQ(read_back(p, status_word(p, kStopping)), kStopping);
}

TEST(ServedCodes, FaultedWithoutANumberIsServedAsDisabled) {
  json doc = vendor();
  doc["signals"]["state"]["values"].erase("faulted");
  doc["signals"]["state"].erase("otherwise");
  const auto p = synbench::testing::parse_or_throw(doc);
  const auto notes = check_served_codes({p});
  ASSERT_EQ(notes.warnings.size(), 1u);
  EXPECT_NE(notes.warnings[0].find("no number for 'faulted'; the emulator serves 'disabled' (0)"), std::string::npos)
      << notes.warnings[0];
  EXPECT_EQ(status_word(p, kFaulted), 0x0000);
}

TEST(ServedCodes, AStateTheMapCannotShowAtAllIsRefused) {
  json doc = vendor();
  doc["signals"]["state"]["values"].erase("running");
  doc["signals"]["state"]["values"].erase("stopping");  // whose fallback is running
  doc["signals"]["state"].erase("otherwise");
  const auto notes = check_served_codes({synbench::testing::parse_or_throw(doc)});
  ASSERT_EQ(notes.errors.size(), 2u);
  EXPECT_EQ(notes.errors[0],
            "profile 'synbench SynRM drive' (synrm_drive): signal state has no number for 'running' (nor an "
            "\"otherwise\"): the twin cannot show that state; map it");
  EXPECT_NE(notes.errors[1].find("no number for 'stopping' (nor an \"otherwise\", nor for its fallback 'running')"),
            std::string::npos)
      << notes.errors[1];
}

TEST(ServedCodes, TheLoadDrivesStateFallsBackToo) {
  json doc = synbench::testing::default_profile_doc(DeviceKind::load_drive);
  doc["signals"]["state"]["values"] = {{"disabled", 0}, {"running", 1}, {"faulted", 3}};
  const auto notes = check_served_codes({synbench::testing::parse_or_throw(doc)});
  ASSERT_EQ(notes.warnings.size(), 1u);
  EXPECT_NE(notes.warnings[0].find("(load_drive): signal state has no number for 'stopping'; the emulator serves "
                                   "'running' (1)"),
            std::string::npos)
      << notes.warnings[0];
}

}  // namespace
}  // namespace synbench::emulator
