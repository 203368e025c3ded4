// `synbench serve`'s settings from three sources, each naming its own errors: flags (--listen),
// environment (SYNBENCH_LISTEN) and a daemon config file (--config FILE, JSON, errors at their
// JSON pointer). A flag beats the environment, which beats the file, which beats the default.
// Pure: the environment is a lookup function and files are read through the twin/bench loaders,
// so every rule is unit-tested (tests/server/cli/serve_options_test.cpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "emulator/twin_config.hpp"

namespace synbench::cli {

struct ServeOptions {
  std::string listen_host = "127.0.0.1";
  std::uint16_t listen_port = 8080;
  std::filesystem::path data_dir = "synbench-data";
  std::filesystem::path web_dir;                 // set from the compiled-in default by the caller
  emulator::TwinConfig twin;                     // the twin's config, and the limits of setpoints
  std::optional<std::filesystem::path> bench;    // a bench config: real drives or `synbench emulate`
  std::string bench_name;                        // stored with every sweep; "" = the host name
  // The store: a SQLite file, or a PostgreSQL URL (docs/database.md); "" = data_dir/synbench.db.
  std::string db;
  std::vector<std::string> allow_hosts;          // extra Host values ("name:port"), lower case
  std::vector<std::string> allow_origins;        // extra WebSocket origins ("scheme://host[:port]")
  // A --listen address other than loopback is refused unless this confirms it: the API is plain
  // HTTP, so bearer tokens would cross the network in the clear.
  bool allow_remote_plain_http = false;
};

// 127.0.0.0/8, ::1 or localhost.
bool is_loopback(const std::string& host);

using EnvLookup = std::function<std::optional<std::string>(const std::string& name)>;
// The process environment (empty values count as unset).
EnvLookup process_env();

// Throws UsageError naming the flag, the variable or the file and JSON pointer. `argv` is the
// subcommand's arguments (without "serve"); --help is the caller's business.
ServeOptions parse_serve_options(const std::vector<std::string>& argv, const EnvLookup& env,
                                 const std::filesystem::path& default_web_dir);

// Parsers shared with tests: "HOST:PORT" ([v6]:port), an origin, a Host value.
void parse_listen(const std::string& text, const std::string& what, std::string& host, std::uint16_t& port);
std::string parse_origin(std::string text, const std::string& what);
std::string parse_host_value(std::string text, const std::string& what);

}  // namespace synbench::cli
