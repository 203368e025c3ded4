// Tests of bench configs: a valid one, and every rejection naming its JSON pointer.
#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivers/bench_config.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

json valid() {
  return json::parse(R"({
    "_comment": "the emulator on loopback",
    "time_scale": 20,
    "poll_period_ms": 5,
    "links": {
      "emu": { "transport": "tcp", "host": "127.0.0.1", "port": 1502, "response_timeout_ms": 100 },
      "rs485": { "transport": "rtu", "device": "/dev/ttyUSB0", "baud": 19200, "parity": "even",
                 "response_timeout_ms": 300, "quiet_ms": 50 }
    },
    "devices": {
      "synrm_drive": { "profile": "default", "link": "emu" },
      "load_drive": { "profile": "default", "link": "emu", "unit_id": 7 },
      "vfc_meter": { "profile": "meters/vfc.json", "link": "rs485" }
    }
  })");
}

std::string errors_of(const json& doc) {
  const BenchConfigResult r = parse_bench_config(doc, "/etc/synbench");
  std::string s;
  for (const auto& e : r.errors) s += e.pointer + ": " + e.reason + "\n";
  return s;
}

TEST(BenchConfig, ParsesAValidConfig) {
  const BenchConfigResult r = parse_bench_config(valid(), "/etc/synbench");
  ASSERT_TRUE(r.config) << errors_of(valid());
  const BenchConfig& c = *r.config;
  EXPECT_DOUBLE_EQ(c.time_scale, 20);
  EXPECT_DOUBLE_EQ(c.poll_period_ms, 5);
  EXPECT_EQ(c.synrm_drive.profile, default_profile_path(DeviceKind::synrm_drive));
  EXPECT_EQ(c.vfc_meter.profile, std::filesystem::path("/etc/synbench/meters/vfc.json"));
  EXPECT_EQ(c.load_drive.unit_id, 7);
  const LinkConfig& emu = c.links.at("emu");
  EXPECT_EQ(emu.transport, LinkTransport::tcp);
  EXPECT_EQ(emu.tcp.port, 1502);
  EXPECT_DOUBLE_EQ(emu.options.response_timeout_s, 0.1);
  const LinkConfig& rs = c.links.at("rs485");
  EXPECT_EQ(rs.rtu.parity, 'E');
  EXPECT_EQ(rs.rtu.baud, 19200);
  EXPECT_DOUBLE_EQ(rs.options.rtu_quiet_s, 0.05);
  EXPECT_FALSE(c.on_twin());
}

TEST(BenchConfig, RetryCountAndBudget) {
  {
    const BenchConfigResult r = parse_bench_config(valid(), "/etc/synbench");
    ASSERT_TRUE(r.config);
    EXPECT_EQ(r.config->retries, 3);  // defaults (docs/bench-config.md)
    EXPECT_DOUBLE_EQ(r.config->retry_budget_ms, 250);
  }
  json d = valid();
  d["retries"] = 7;
  d["retry_budget_ms"] = 120;
  const BenchConfigResult r = parse_bench_config(d, "/etc/synbench");
  ASSERT_TRUE(r.config) << errors_of(d);
  EXPECT_EQ(r.config->retries, 7);
  EXPECT_DOUBLE_EQ(r.config->retry_budget_ms, 120);
  d["retries"] = 11;
  d["retry_budget_ms"] = -1;
  const std::string e = errors_of(d);
  EXPECT_NE(e.find("/retries: 11 is outside [0, 10]"), std::string::npos) << e;
  EXPECT_NE(e.find("/retry_budget_ms: -1 is outside [0, 60000]"), std::string::npos) << e;
}

TEST(BenchConfig, EveryProblemNamesItsField) {
  json d = valid();
  d["time_scale"] = 0;
  d["links"]["emu"]["port"] = 70000;
  d["links"]["emu"]["colour"] = "red";
  d["links"]["rs485"]["parity"] = "mark";
  d["devices"]["vfc_meter"]["link"] = "nowhere";
  d["devices"]["load_drive"]["unit_id"] = 0;
  d.erase("poll_period_ms");
  const std::string e = errors_of(d);
  EXPECT_NE(e.find("/time_scale: 0 is outside"), std::string::npos) << e;
  EXPECT_NE(e.find("/links/emu/port: 70000 is outside"), std::string::npos) << e;
  EXPECT_NE(e.find("/links/emu/colour: unknown field"), std::string::npos) << e;
  EXPECT_NE(e.find("/links/rs485/parity: unknown parity 'mark'"), std::string::npos) << e;
  EXPECT_NE(e.find("/devices/vfc_meter/link: 'nowhere' is not one of /links"), std::string::npos) << e;
  EXPECT_NE(e.find("/devices/load_drive/unit_id: 0 is outside"), std::string::npos) << e;
}

TEST(BenchConfig, TheUncertaintySectionOverridesItsDefaultsAndRefusesNonsense) {
  {
    const BenchConfigResult r = parse_bench_config(valid(), "/etc/synbench");
    ASSERT_TRUE(r.config);
    EXPECT_DOUBLE_EQ(r.config->uncertainty.meter_clock_u_ppm, UncertaintyConfig{}.meter_clock_u_ppm);
  }
  json d = valid();
  d["uncertainty"] = json::parse(R"({"meter_clock_u_ppm": 20, "udc_gain_u_pct": 0.25, "encoder_counts_per_rev": 8192})");
  const BenchConfigResult r = parse_bench_config(d, "/etc/synbench");
  ASSERT_TRUE(r.config) << errors_of(d);
  EXPECT_DOUBLE_EQ(r.config->uncertainty.meter_clock_u_ppm, 20);
  EXPECT_DOUBLE_EQ(r.config->uncertainty.udc_gain_u_pct, 0.25);
  EXPECT_DOUBLE_EQ(r.config->uncertainty.encoder_counts_per_rev, 8192);
  EXPECT_DOUBLE_EQ(r.config->uncertainty.vfc_f0_u_Hz, UncertaintyConfig{}.vfc_f0_u_Hz);  // not given: default
  d["uncertainty"] = json::parse(R"({"udc_gain_u_pct": 101, "torque_offset_u_Nm": -1, "shunt_u_pct": 1,
                                     "encoder_counts_per_rev": 0})");
  const std::string e = errors_of(d);
  EXPECT_NE(e.find("/uncertainty/udc_gain_u_pct: 101 is outside [0, 100]"), std::string::npos) << e;
  EXPECT_NE(e.find("/uncertainty/torque_offset_u_Nm: -1 is outside"), std::string::npos) << e;
  EXPECT_NE(e.find("/uncertainty/shunt_u_pct: unknown field"), std::string::npos) << e;
  EXPECT_NE(e.find("/uncertainty/encoder_counts_per_rev: 0 is outside"), std::string::npos) << e;
}

TEST(BenchConfig, TheTwinIsAllOrNothing) {
  json d = valid();
  d["links"]["twin"] = {{"transport", "twin"}};
  d["devices"]["synrm_drive"]["link"] = "twin";
  EXPECT_NE(errors_of(d).find("/devices: the in-process twin cannot be mixed"), std::string::npos);
  for (const char* k : {"synrm_drive", "load_drive", "vfc_meter"}) d["devices"][k]["link"] = "twin";
  const BenchConfigResult r = parse_bench_config(d, "/");
  ASSERT_TRUE(r.config) << errors_of(d);
  EXPECT_TRUE(r.config->on_twin());
}

TEST(BenchConfig, MissingPartsAreNamed) {
  const std::string e = errors_of(json::parse(R"({"links": {"x": {"transport": "udp"}}, "devices": {}})"));
  EXPECT_NE(e.find("/links/x/transport: unknown transport 'udp'"), std::string::npos) << e;
  EXPECT_NE(e.find("/devices/synrm_drive: required device is missing"), std::string::npos) << e;
  EXPECT_NE(errors_of(json::object()).find("/links: required field is missing"), std::string::npos);
}

TEST(BenchConfig, ProfilesAreLoadedAndUnitIdsOverridden) {
  json d = valid();
  d["devices"]["vfc_meter"]["profile"] = "default";
  const BenchConfigResult r = parse_bench_config(d, "/");
  ASSERT_TRUE(r.config);
  std::vector<ProfileError> errors;
  const auto profiles = load_bench_profiles(*r.config, errors);
  ASSERT_TRUE(profiles) << (errors.empty() ? "" : errors.front().reason);
  EXPECT_EQ(profiles->load_drive.unit_id, 7);
  for (const ProfileSignal& s : profiles->load_drive.signals) EXPECT_EQ(s.unit_id, 7) << s.name;
  EXPECT_EQ(profiles->synrm_drive.unit_id, 1);
}

TEST(BenchConfig, AProfileOfTheWrongKindOrUnreadableIsNamed) {
  json d = valid();
  d["devices"]["vfc_meter"]["profile"] = default_profile_path(DeviceKind::load_drive).string();
  d["devices"]["load_drive"]["profile"] = "/nonexistent/profile.json";
  const BenchConfigResult r = parse_bench_config(d, "/");
  ASSERT_TRUE(r.config);
  std::vector<ProfileError> errors;
  EXPECT_FALSE(load_bench_profiles(*r.config, errors));
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].pointer, "/devices/load_drive/profile");
  EXPECT_EQ(errors[1].pointer, "/devices/vfc_meter/profile");
  EXPECT_NE(errors[1].reason.find("not vfc_meter"), std::string::npos) << errors[1].reason;
}

TEST(BenchConfig, FilesResolveProfilesAgainstTheirFolder) {
  const auto dir = std::filesystem::temp_directory_path() / "synbench_bench_config_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bench.json") << valid().dump();
  const BenchConfigResult r = load_bench_config(dir / "bench.json");
  ASSERT_TRUE(r.config);
  EXPECT_EQ(r.config->vfc_meter.profile, dir / "meters/vfc.json");
  std::ofstream(dir / "bad.json") << "{ nope";
  const BenchConfigResult bad = load_bench_config(dir / "bad.json");
  ASSERT_EQ(bad.errors.size(), 1u);
  EXPECT_NE(bad.errors[0].reason.find("not valid JSON"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(BenchConfig, TheShippedExamplesParse) {
  for (const char* name : {"bench-emulate.json", "bench-twin.json"}) {
    const BenchConfigResult r = load_bench_config(std::filesystem::path(SYNBENCH_SOURCE_DIR) / "config" / name);
    ASSERT_TRUE(r.config) << name << ": " << (r.errors.empty() ? "" : r.errors.front().pointer + " " + r.errors.front().reason);
    std::vector<ProfileError> errors;
    EXPECT_TRUE(load_bench_profiles(*r.config, errors)) << name;
  }
}

TEST(BenchConfig, TheHardwareExampleOfTheDocsParses) {
  // docs/bench-config.md's third example, less the third-party profile file it names.
  std::ifstream in(std::filesystem::path(SYNBENCH_SOURCE_DIR) / "docs" / "bench-config.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const auto at = doc.find("\"_comment\": \"Lab 3");
  ASSERT_NE(at, std::string::npos);
  const auto begin = doc.rfind('{', at), end = doc.find("\n```", at);
  const BenchConfigResult r = parse_bench_config(json::parse(doc.substr(begin, end - begin)), "/etc/synbench");
  ASSERT_TRUE(r.config) << errors_of(json::parse(doc.substr(begin, end - begin)));
  EXPECT_EQ(r.config->vfc_meter.unit_id, 12);
  EXPECT_EQ(r.config->links.at("rs485").rtu.parity, 'E');
}

}  // namespace
}  // namespace synbench::drivers
