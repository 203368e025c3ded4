// serve_options: precedence flag > environment > config file > default, and every error naming
// its source (the flag, the variable, the file and JSON pointer).
#include "server/cli/serve_options.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "server/cli/args.hpp"

namespace synbench::cli {
namespace {

namespace fs = std::filesystem;

struct Env {
  std::map<std::string, std::string> vars;
  EnvLookup lookup() const {
    return [this](const std::string& n) -> std::optional<std::string> {
      auto it = vars.find(n);
      if (it == vars.end()) return std::nullopt;
      return it->second;
    };
  }
};

fs::path write_file(const std::string& name, const std::string& text) {
  const auto dir = fs::temp_directory_path() / "synbench-serve-options-test";
  fs::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// The message of the UsageError parse throws, or "" when it does not.
std::string error_of(const std::vector<std::string>& argv, const Env& env = {}) {
  try {
    parse_serve_options(argv, env.lookup(), "/web");
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(ServeOptions, DefaultsAreLoopbackAndTheCompiledWebDir) {
  const auto o = parse_serve_options({}, Env{}.lookup(), "/src/web/dist");
  EXPECT_EQ(o.listen_host, "127.0.0.1");
  EXPECT_EQ(o.listen_port, 8080);
  EXPECT_EQ(o.data_dir, "synbench-data");
  EXPECT_EQ(o.web_dir, "/src/web/dist");
  EXPECT_FALSE(o.bench);
  EXPECT_TRUE(o.allow_hosts.empty());
  EXPECT_DOUBLE_EQ(o.twin.firmware.max_speed_rpm, emulator::TwinConfig{}.firmware.max_speed_rpm);
}

TEST(ServeOptions, FlagBeatsEnvironmentBeatsFile) {
  const auto cfg = write_file("precedence.json", R"({"listen": "127.0.0.1:7001", "data_dir": "data-from-file",
    "allow_hosts": ["bench.lab:7001"], "_comment": "ignored"})");
  Env env;
  env.vars["SYNBENCH_CONFIG"] = cfg.string();
  auto o = parse_serve_options({}, env.lookup(), "/web");
  EXPECT_EQ(o.listen_port, 7001);
  EXPECT_EQ(o.data_dir, cfg.parent_path() / "data-from-file");  // relative to the file
  EXPECT_EQ(o.allow_hosts, std::vector<std::string>{"bench.lab:7001"});
  env.vars["SYNBENCH_LISTEN"] = "127.0.0.1:7002";
  env.vars["SYNBENCH_ALLOW_HOSTS"] = "A.lab:1, b.lab:2,";
  o = parse_serve_options({}, env.lookup(), "/web");
  EXPECT_EQ(o.listen_port, 7002);
  EXPECT_EQ(o.allow_hosts, (std::vector<std::string>{"a.lab:1", "b.lab:2"}));
  o = parse_serve_options({"--listen", "127.0.0.1:7003", "--allow-host", "c.lab:3"}, env.lookup(), "/web");
  EXPECT_EQ(o.listen_port, 7003);
  EXPECT_EQ(o.allow_hosts, std::vector<std::string>{"c.lab:3"});
  EXPECT_EQ(o.data_dir, cfg.parent_path() / "data-from-file");  // untouched by the others
}

TEST(ServeOptions, TheStoreAndTheBenchNameFromAFlagOrTheEnvironment) {
  auto o = parse_serve_options({}, Env{}.lookup(), "/web");
  EXPECT_EQ(o.db, "") << "the data directory's synbench.db";
  EXPECT_EQ(o.bench_name, "") << "the host name";
  Env env;
  env.vars["SYNBENCH_DB"] = "postgresql://lab@db.lab/lab";
  env.vars["SYNBENCH_BENCH_NAME"] = "bench-2";
  o = parse_serve_options({}, env.lookup(), "/web");
  EXPECT_EQ(o.db, "postgresql://lab@db.lab/lab");
  EXPECT_EQ(o.bench_name, "bench-2");
  o = parse_serve_options({"--db", "host=/run/pg dbname=lab", "--bench-name", "bench-3"}, env.lookup(), "/web");
  EXPECT_EQ(o.db, "host=/run/pg dbname=lab");
  EXPECT_EQ(o.bench_name, "bench-3");
  EXPECT_NE(error_of({"--db", ""}).find("--db"), std::string::npos);
  // The config file's keys: a file relative to it, a URL as given.
  const auto cfg = write_file("db.json", R"({"db": "lab.db", "bench_name": "bench-4"})");
  o = parse_serve_options({"--config", cfg.string()}, Env{}.lookup(), "/web");
  EXPECT_EQ(o.db, (cfg.parent_path() / "lab.db").string());
  EXPECT_EQ(o.bench_name, "bench-4");
  const auto url_cfg = write_file("db-url.json", R"({"db": "postgresql://lab@db.lab/lab"})");
  EXPECT_EQ(parse_serve_options({"--config", url_cfg.string()}, Env{}.lookup(), "/web").db, "postgresql://lab@db.lab/lab");
}

TEST(ServeOptions, TwinSectionOverlaysTheDefaults) {
  const auto cfg = write_file("twin.json", R"({"twin": {"firmware": {"max_speed_rpm": 1200}}})");
  const auto o = parse_serve_options({"--config", cfg.string()}, Env{}.lookup(), "/web");
  EXPECT_DOUBLE_EQ(o.twin.firmware.max_speed_rpm, 1200);
  EXPECT_DOUBLE_EQ(o.twin.firmware.overspeed_trip_rpm, emulator::TwinConfig{}.firmware.overspeed_trip_rpm);
}

TEST(ServeOptions, ErrorsNameTheirSource) {
  EXPECT_NE(error_of({"--listen", "nonsense"}).find("--listen"), std::string::npos);
  Env env;
  env.vars["SYNBENCH_LISTEN"] = "127.0.0.1:99999";
  EXPECT_NE(error_of({}, env).find("SYNBENCH_LISTEN"), std::string::npos);
  EXPECT_NE(error_of({}, env).find("99999"), std::string::npos);
  env.vars.clear();
  env.vars["SYNBENCH_ALLOW_ORIGINS"] = "http://ok.lab,ftp://bad";
  EXPECT_NE(error_of({}, env).find("SYNBENCH_ALLOW_ORIGINS"), std::string::npos);
  EXPECT_NE(error_of({"--allow-origin", "http://x.lab/path"}).find("--allow-origin"), std::string::npos);
  EXPECT_NE(error_of({"--allow-host", "http://x.lab"}).find("--allow-host"), std::string::npos);
  EXPECT_NE(error_of({"--config", "/nonexistent/synbench.json"}).find("cannot read"), std::string::npos);

  const auto unknown = write_file("unknown.json", R"({"listen": "127.0.0.1:1", "lissten": 2})");
  const auto e1 = error_of({"--config", unknown.string()});
  EXPECT_NE(e1.find("/lissten"), std::string::npos) << e1;
  EXPECT_NE(e1.find("/lissten: unknown field"), std::string::npos) << e1;
  const auto typed = write_file("typed.json", R"({"allow_hosts": ["ok.lab:1", 5]})");
  EXPECT_NE(error_of({"--config", typed.string()}).find("/allow_hosts/1"), std::string::npos);
  const auto bad_json = write_file("bad.json", R"({"listen": )");
  EXPECT_NE(error_of({"--config", bad_json.string()}).find("not valid JSON"), std::string::npos);
  const auto bad_twin = write_file("bad_twin.json", R"({"twin": {"firmware": {"max_speed_rpm": -5}}})");
  const auto e2 = error_of({"--config", bad_twin.string()});
  EXPECT_NE(e2.find("/twin"), std::string::npos) << e2;
  EXPECT_NE(e2.find("max_speed_rpm"), std::string::npos) << e2;
  EXPECT_NE(error_of({"extra"}).find("unexpected argument"), std::string::npos);
  EXPECT_NE(error_of({"--data-dir", ""}).find("--data-dir"), std::string::npos);
}

// Three mistakes in one config file: one UsageError names all three, each at its JSON pointer,
// in the wording of the other loaders (drivers/json_reader.hpp).
TEST(ServeOptions, ConfigFileReportsEveryMistakeAtOnce) {
  const auto three = write_file("three.json", R"({"_comment": "fine", "listen": 8080, "lissten": "x",
                                                  "allow_origins": ["https://ok.lab", "ftp://bad.lab"]})");
  const auto e = error_of({"--config", three.string()});
  EXPECT_EQ(e, "--config: " + three.string() +
                   ": /lissten: unknown field; /listen: must be a non-empty string; "
                   "/allow_origins/1: 'ftp://bad.lab' is not an origin (scheme://host[:port], no path)")
      << e;
  const auto more = write_file("more.json", R"({"allow_remote_plain_http": "yes", "twin": 3, "allow_hosts": "a.lab",
                                                 "data_dir": ""})");
  const auto e2 = error_of({"--config", more.string()});
  EXPECT_NE(e2.find("/allow_remote_plain_http: must be true or false"), std::string::npos) << e2;
  EXPECT_NE(e2.find("/twin: must be a twin config object or a file name"), std::string::npos) << e2;
  EXPECT_NE(e2.find("/allow_hosts: must be a list of strings"), std::string::npos) << e2;
  EXPECT_NE(e2.find("/data_dir: must be a non-empty string"), std::string::npos) << e2;
  const auto top = write_file("top.json", "[1]");
  EXPECT_EQ(error_of({"--config", top.string()}), "--config: " + top.string() + ": (document): must be a JSON object");
}

TEST(ServeOptions, ParsersAcceptWhatTheyShould) {
  std::string host;
  std::uint16_t port = 0;
  parse_listen("[::1]:8081", "--listen", host, port);
  EXPECT_EQ(host, "::1");
  EXPECT_EQ(port, 8081);
  EXPECT_EQ(parse_origin("HTTPS://Bench.Lab:8443", "x"), "https://bench.lab:8443");
  EXPECT_EQ(parse_host_value("Bench.Lab:8080", "x"), "bench.lab:8080");
}

}  // namespace
}  // namespace synbench::cli

namespace synbench::cli {
namespace {

// Plain HTTP beyond loopback carries bearer tokens in the clear: refused unless confirmed.
TEST(ServeOptions, ANonLoopbackListenNeedsItsConfirmation) {
  const auto refused = [](const std::vector<std::string>& argv) {
    try {
      parse_serve_options(argv, [](const std::string&) { return std::optional<std::string>(); }, "/web");
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refused({"--listen", "0.0.0.0:8080"}).find("not a loopback address"), std::string::npos);
  EXPECT_NE(refused({"--listen", "192.0.2.7:8080"}).find("--allow-remote-plain-http"), std::string::npos);
  EXPECT_EQ(refused({"--listen", "0.0.0.0:8080", "--allow-remote-plain-http"}), "");
  EXPECT_EQ(refused({"--listen", "127.0.0.2:8080"}), "");
  EXPECT_EQ(refused({"--listen", "[::1]:8080"}), "");
}

}  // namespace
}  // namespace synbench::cli
