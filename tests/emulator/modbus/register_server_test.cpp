// Tests of the profile-driven register server at the PDU level, with a provider that records
// writes: addressing, encoding, exceptions, broadcast, stuck values.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "drivers/error.hpp"
#include "drivers/profile/device_profile.hpp"
#include "emulator/modbus/modbus_pdu.hpp"
#include "emulator/modbus/register_server.hpp"
#include "tests/drivers/default_profiles.hpp"

namespace synbench::emulator {
namespace {

using namespace modbus;

using testing::default_profiles;

class RecordingProvider final : public SignalProvider {
 public:
  double read_signal(drivers::DeviceKind, const drivers::ProfileSignal& s) override {
    const auto it = values.find(s.name);
    return it == values.end() ? 0.0 : it->second;
  }
  std::error_code write_signal(drivers::DeviceKind device, const drivers::ProfileSignal& s, double v) override {
    writes.push_back({device, s.name, v});
    return answer;
  }
  struct Write {
    drivers::DeviceKind device;
    std::string signal;
    double value;
  };
  std::map<std::string, double> values;
  std::vector<Write> writes;
  std::error_code answer;
};

struct Server : ::testing::Test {
  RecordingProvider provider;
  RegisterServer server{default_profiles(), provider};
  std::uint8_t reply[kMaxPdu];

  std::vector<std::uint8_t> ask(std::uint8_t unit, std::vector<std::uint8_t> pdu) {
    const std::size_t n = server.handle(unit, pdu, reply);
    return {reply, reply + n};
  }
  static std::vector<std::uint8_t> read_req(std::uint8_t fn, std::uint16_t address, std::uint16_t count) {
    std::vector<std::uint8_t> r(5);
    r[0] = fn;
    put16(&r[1], address);
    put16(&r[3], count);
    return r;
  }
  static std::vector<std::uint8_t> write_regs(std::uint16_t address, std::vector<std::uint16_t> words) {
    std::vector<std::uint8_t> r(6 + 2 * words.size());
    r[0] = kWriteMultipleRegisters;
    put16(&r[1], address);
    put16(&r[3], static_cast<std::uint16_t>(words.size()));
    r[5] = static_cast<std::uint8_t>(2 * words.size());
    for (std::size_t i = 0; i < words.size(); ++i) put16(&r[6 + 2 * i], words[i]);
    return r;
  }
};

TEST_F(Server, ReadsEncodeAsTheProfileSays) {
  provider.values["speed_rpm"] = 1.5;   // f32 ABCD at input 16-17: 0x3FC0 0x0000
  provider.values["udc_V"] = 424.5;     // u16, scale 0.1 at input 30
  provider.values["state"] = 1;
  const auto r = ask(1, read_req(kReadInputRegisters, 16, 16));
  ASSERT_EQ(r.size(), 2u + 32u);
  EXPECT_EQ(r[1], 32);
  EXPECT_EQ(get16(&r[2]), 0x3FC0);
  EXPECT_EQ(get16(&r[4]), 0x0000);
  EXPECT_EQ(get16(&r[2 + 2 * 14]), 4245);
  const auto s = ask(1, read_req(kReadInputRegisters, 0, 2));
  EXPECT_EQ(get16(&s[2]), 1);
}

TEST_F(Server, ValuesBeyondTheLimitsSaturate) {
  provider.values["temp_C"] = 400;  // limits -50..250
  const auto r = ask(1, read_req(kReadInputRegisters, 31, 1));
  EXPECT_EQ(get16(&r[2]), 3000);  // (250 + 50) / 0.1
}

TEST_F(Server, BitsArePackedLowFirst) {
  provider.values["voltage_limited"] = 1;
  const auto r = ask(1, read_req(kReadDiscreteInputs, 0, 1));
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[2], 1);
}

TEST_F(Server, AddressesBeyondTheMapAreIllegal) {
  // The SynRM drive's last input register is 183 (window_batch_speed_meas_rpm's last value).
  EXPECT_EQ(ask(1, read_req(kReadInputRegisters, 182, 2)).size(), 6u);
  EXPECT_EQ(ask(1, read_req(kReadInputRegisters, 183, 2)), (std::vector<std::uint8_t>{0x84, kIllegalDataAddress}));
  EXPECT_EQ(ask(3, read_req(kReadCoils, 0, 5)), (std::vector<std::uint8_t>{0x81, kIllegalDataAddress}));
  EXPECT_EQ(ask(1, read_req(kReadInputRegisters, 0, 126)), (std::vector<std::uint8_t>{0x84, kIllegalDataValue}));
  EXPECT_EQ(ask(1, {0x2B, 0x0E}), (std::vector<std::uint8_t>{0xAB, kIllegalFunction}));
}

TEST_F(Server, WritesMustCoverWholeWritableSignals) {
  // Half of the f32 speed setpoint.
  EXPECT_EQ(ask(1, write_regs(17, {0})), (std::vector<std::uint8_t>{0x90, kIllegalDataAddress}));
  // Holding 1 maps nothing.
  EXPECT_EQ(ask(1, write_regs(1, {0})), (std::vector<std::uint8_t>{0x90, kIllegalDataAddress}));
  // Speed 1.5 rpm and angle 52.00 deg in one request.
  const auto r = ask(1, write_regs(16, {0x3FC0, 0x0000, 5200}));
  ASSERT_EQ(r.size(), 5u);
  ASSERT_EQ(provider.writes.size(), 2u);
  EXPECT_EQ(provider.writes[0].signal, "speed_setpoint_rpm");
  EXPECT_DOUBLE_EQ(provider.writes[0].value, 1.5);
  EXPECT_DOUBLE_EQ(provider.writes[1].value, 52.0);
}

TEST_F(Server, AValueOutsideTheLimitsIsRefusedAndNothingApplied) {
  // 1.5 rpm is fine, the angle 200.00 deg is not: neither is applied.
  EXPECT_EQ(ask(1, write_regs(16, {0x3FC0, 0x0000, 20000})), (std::vector<std::uint8_t>{0x90, kIllegalDataValue}));
  EXPECT_TRUE(provider.writes.empty());
  // An estimator code the catalogue does not have.
  EXPECT_EQ(ask(1, write_regs(20, {9})), (std::vector<std::uint8_t>{0x90, kIllegalDataValue}));
}

TEST_F(Server, TheProvidersRefusalsBecomeExceptions) {
  const std::vector<std::uint8_t> set_estimator = write_regs(20, {1});
  provider.answer = make_error_code(errc::not_supported);
  EXPECT_EQ(ask(1, set_estimator), (std::vector<std::uint8_t>{0x90, kIllegalDataValue}));
  provider.answer = make_error_code(errc::busy);
  EXPECT_EQ(ask(1, set_estimator), (std::vector<std::uint8_t>{0x90, kServerDeviceBusy}));
  provider.answer = make_error_code(errc::device_fault);
  EXPECT_EQ(ask(1, set_estimator), (std::vector<std::uint8_t>{0x90, kServerDeviceFailure}));
}

TEST_F(Server, SingleCoilAndRegisterWritesEchoTheRequest) {
  const std::vector<std::uint8_t> coil{kWriteSingleCoil, 0, 1, 0xFF, 0x00};  // fault_reset
  EXPECT_EQ(ask(2, coil), coil);
  ASSERT_EQ(provider.writes.size(), 1u);
  EXPECT_EQ(provider.writes[0].device, drivers::DeviceKind::load_drive);
  EXPECT_EQ(provider.writes[0].signal, "fault_reset");
  const std::vector<std::uint8_t> bad{kWriteSingleCoil, 0, 1, 0x12, 0x34};
  EXPECT_EQ(ask(2, bad), (std::vector<std::uint8_t>{0x85, kIllegalDataValue}));
  const std::vector<std::uint8_t> reg{kWriteSingleRegister, 0, 19, 0, 1};  // pwm_scheme aspwm
  EXPECT_EQ(ask(1, reg), reg);
}

TEST_F(Server, ABroadcastWriteReachesEveryUnitAndIsNotAnswered) {
  // Window start (coil 2) on all three devices at once.
  EXPECT_TRUE(ask(0, {kWriteSingleCoil, 0, 2, 0xFF, 0x00}).empty());
  ASSERT_EQ(provider.writes.size(), 3u);
  EXPECT_EQ(provider.writes[2].device, drivers::DeviceKind::vfc_meter);
  EXPECT_TRUE(ask(0, read_req(kReadCoils, 0, 1)).empty());
}

TEST_F(Server, AStuckSignalKeepsItsValue) {
  provider.values["speed_rpm"] = 100;
  ASSERT_FALSE(server.stick(1, "speed_rpm"));
  const auto before = ask(1, read_req(kReadInputRegisters, 16, 2));
  provider.values["speed_rpm"] = 200;
  EXPECT_EQ(ask(1, read_req(kReadInputRegisters, 16, 2)), before);
  server.unstick_all();
  EXPECT_NE(ask(1, read_req(kReadInputRegisters, 16, 2)), before);
  EXPECT_EQ(server.stick(3, "speed_rpm"), errc::not_supported);
}

TEST_F(Server, ServesTheProfilesUnitIds) {
  EXPECT_TRUE(server.serves(1));
  EXPECT_TRUE(server.serves(3));
  EXPECT_FALSE(server.serves(4));
}

}  // namespace
}  // namespace synbench::emulator
