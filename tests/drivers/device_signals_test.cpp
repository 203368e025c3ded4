// Tests of the signal tables of the device structs: every table signal is one the default
// profile maps, with the catalogue role its table implies, and the window schema treats a
// window table's signals as window signals; a member converts by its type.
#include "drivers/device_signals.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "drivers/json.hpp"
#include "drivers/profile/device_profile.hpp"
#include "tests/drivers/default_profiles.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;


std::string describe(const std::vector<ProfileError>& errors) {
  std::string s;
  for (const ProfileError& e : errors) s += "\n  '" + e.pointer + "': " + e.reason;
  return s;
}

// One table as the tests see it: its signals, the device kind and the profile that maps them,
// and the catalogue role each signal must have.
struct Table {
  const char* name;
  DeviceKind kind;
  std::filesystem::path profile;
  SignalRole role;
  std::vector<std::string_view> signals;
};

template <class S, std::size_t N>
std::vector<std::string_view> signals_of(const SignalField<S> (&table)[N]) {
  std::vector<std::string_view> out;
  for (const auto& f : table) out.push_back(f.signal);
  return out;
}

std::vector<Table> tables() {
  const auto test_profile = [](const char* f) { return std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / f; };
  const auto synrm = default_profile_path(DeviceKind::synrm_drive);
  const auto load = default_profile_path(DeviceKind::load_drive);
  const auto meter = default_profile_path(DeviceKind::vfc_meter);
  return {
      {"kSynrmTelemetrySignals", DeviceKind::synrm_drive, synrm, SignalRole::telemetry, signals_of(kSynrmTelemetrySignals)},
      {"kSynrmWindowSignals", DeviceKind::synrm_drive, synrm, SignalRole::window_result, signals_of(kSynrmWindowSignals)},
      {"kSynrmHostMeans", DeviceKind::synrm_drive, synrm, SignalRole::telemetry, signals_of(kSynrmHostMeans)},
      {"kLoadTelemetrySignals", DeviceKind::load_drive, load, SignalRole::telemetry, signals_of(kLoadTelemetrySignals)},
      {"kLoadWindowSignals", DeviceKind::load_drive, load, SignalRole::window_result, signals_of(kLoadWindowSignals)},
      {"kLoadHostMeans", DeviceKind::load_drive, load, SignalRole::telemetry, signals_of(kLoadHostMeans)},
      {"kMeterGateSignals", DeviceKind::vfc_meter, meter, SignalRole::window_result, signals_of(kMeterGateSignals)},
      // The default meter is a gate; the power meter's profile is a test profile.
      {"kMeterPowerMeans", DeviceKind::vfc_meter, test_profile("meter_power.json"), SignalRole::telemetry,
       signals_of(kMeterPowerMeans)},
  };
}

TEST(DeviceSignals, EveryTableSignalIsMappedByTheProfileWithItsTablesRole) {
  for (const Table& t : tables()) {
    const ProfileParseResult r = load_device_profile(t.profile);
    ASSERT_TRUE(r.profile) << t.profile << describe(r.errors);
    EXPECT_EQ(r.profile->kind, t.kind) << t.name;
    for (const std::string_view s : t.signals) {
      const ProfileSignal* p = r.profile->find(s);
      ASSERT_NE(p, nullptr) << t.name << ": " << s << " is not in " << t.profile;
      EXPECT_TRUE(p->readable()) << t.name << ": " << s;
      EXPECT_EQ(p->role, t.role) << t.name << ": " << s;
    }
  }
}

template <class S, std::size_t N>
void expect_one_to_one(const SignalField<S> (&table)[N], const char* name) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j) {
      EXPECT_NE(table[i].signal, table[j].signal) << name;
      EXPECT_FALSE(table[i].member == table[j].member)
          << name << ": " << table[i].signal << " and " << table[j].signal << " fill one member";
    }
}

// Both sides read the same table, so a signal pointed at the wrong member would still round
// trip; two signals on one member would leave another member never filled.
TEST(DeviceSignals, EachTableMapsSignalsAndMembersOneToOne) {
  expect_one_to_one(kSynrmTelemetrySignals, "kSynrmTelemetrySignals");
  expect_one_to_one(kSynrmWindowSignals, "kSynrmWindowSignals");
  expect_one_to_one(kSynrmHostMeans, "kSynrmHostMeans");
  expect_one_to_one(kLoadTelemetrySignals, "kLoadTelemetrySignals");
  expect_one_to_one(kLoadWindowSignals, "kLoadWindowSignals");
  expect_one_to_one(kLoadHostMeans, "kLoadHostMeans");
  expect_one_to_one(kMeterGateSignals, "kMeterGateSignals");
  expect_one_to_one(kMeterPowerMeans, "kMeterPowerMeans");
}

// A drive's window table signal mapped without the rest of the window signals makes the window
// schema refuse the profile, naming the signal: the schema and the table agree on what a
// window signal is. (Without any window signal the same profile is a host-kept window.)
TEST(DeviceSignals, TheWindowSchemaTakesADrivesWindowTableSignalsAsWindowSignals) {
  const auto without_window = [](DeviceKind kind, std::string_view keep) {
    json doc = testing::json_doc(default_profile_path(kind));
    json& map = doc["signals"];
    std::vector<std::string> drop;
    for (const auto& [name, _] : map.items())
      if (name.starts_with("window_") && name != keep) drop.push_back(name);
    for (const std::string& n : drop) map.erase(n);
    doc["poll_period_ms"] = 100;
    return parse_device_profile(doc);
  };
  const auto check = [&](DeviceKind kind, const std::vector<std::string_view>& signals) {
    const ProfileParseResult host = without_window(kind, "");
    ASSERT_TRUE(host.profile) << describe(host.errors);
    for (const std::string_view keep : signals) {
      const ProfileParseResult r = without_window(kind, keep);
      EXPECT_FALSE(r.profile) << keep;
      bool named = false;
      for (const ProfileError& e : r.errors)
        named = named || e.pointer == "/signals/" + std::string(keep) || e.reason.find(keep) != std::string::npos;
      EXPECT_TRUE(named) << keep << describe(r.errors);
    }
  };
  check(DeviceKind::synrm_drive, signals_of(kSynrmWindowSignals));
  check(DeviceKind::load_drive, signals_of(kLoadWindowSignals));
}

// A meter table's signal left out of its meter kind's profile is a missing member of its group.
TEST(DeviceSignals, TheWindowSchemaRequiresAMeterTablesSignalsForItsMeterKind) {
  const auto check = [](const std::filesystem::path& profile, const std::vector<std::string_view>& signals,
                        const std::string& meter) {
    for (const std::string_view s : signals) {
      json doc = testing::json_doc(profile);
      doc["signals"].erase(std::string(s));
      const ProfileParseResult r = parse_device_profile(doc);
      ASSERT_EQ(r.errors.size(), 1u) << s << describe(r.errors);
      EXPECT_EQ(r.errors[0].pointer, "/signals/" + std::string(s));
      EXPECT_NE(r.errors[0].reason.find("for meter " + meter), std::string::npos) << r.errors[0].reason;
    }
  };
  check(default_profile_path(DeviceKind::vfc_meter), signals_of(kMeterGateSignals), "gate");
  check(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / "meter_power.json", signals_of(kMeterPowerMeans), "power");
}

TEST(DeviceSignals, AMemberConvertsByItsType) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SynrmTelemetry t;
  t.im_A = 9;
  t.temp_C = 40;
  t.voltage_limited = true;
  assign(t, &SynrmTelemetry::im_A, nan);  // a double the profile lacks reads 0
  assign(t, &SynrmTelemetry::temp_C, nan);  // an optional one is empty
  assign(t, &SynrmTelemetry::voltage_limited, nan);
  EXPECT_EQ(t.im_A, 0);
  EXPECT_FALSE(t.temp_C);
  EXPECT_FALSE(t.voltage_limited);
  assign(t, &SynrmTelemetry::voltage_limited, 1);
  assign(t, &SynrmTelemetry::state, 3);
  assign(t, &SynrmTelemetry::fault, 5);
  assign(t, &SynrmTelemetry::temp_C, 61.5);
  EXPECT_TRUE(t.voltage_limited);
  EXPECT_EQ(t.state, DriveState::faulted);
  EXPECT_EQ(t.fault, Fault::overtemperature);
  EXPECT_EQ(t.temp_C, 61.5);
  EXPECT_EQ(number(t, &SynrmTelemetry::state), 3.0);
  EXPECT_EQ(number(t, &SynrmTelemetry::voltage_limited), 1.0);
  EXPECT_EQ(number(t, &SynrmTelemetry::temp_C), 61.5);
  EXPECT_EQ(number(t, &SynrmTelemetry::pos_err_deg), std::nullopt);

  MeterReading m;
  assign(m, &MeterReading::counts_m, 4294967295.0);
  EXPECT_EQ(m.counts_m, 4294967295u);
  EXPECT_EQ(number(m, &MeterReading::counts_m), 4294967295.0);
}

TEST(DeviceSignals, EstimatesPresentHasTheBitOfEachResultAWindowHas) {
  SynrmWindow w;
  EXPECT_EQ(estimates_present(w), 0u);
  w.pos_err_mean_deg = 1;
  w.lq_est_H = 0.01;
  EXPECT_EQ(estimates_present(w), 1u | 4u);
  w.rs_est_ohm = 0.5;
  w.ld_est_H = 0.02;
  EXPECT_EQ(estimates_present(w), 15u);
}

}  // namespace
}  // namespace synbench::drivers
