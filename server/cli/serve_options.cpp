// Flags, environment and config file of `synbench serve`; see serve_options.hpp.
#include "server/cli/serve_options.hpp"

#include "db/store.hpp"

#include <cstdlib>

#include "drivers/json.hpp"

#include "drivers/json_file.hpp"
#include "drivers/json_reader.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"

namespace synbench::cli {
namespace {

std::string lower(std::string s) {
  for (char& c : s) if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i <= list.size();) {
    const std::size_t j = std::min(list.find(',', i), list.size());
    // Items are trimmed: "a.lab:1, b.lab:2" is two items.
    std::size_t b = i, e = j;
    while (b < e && (list[b] == ' ' || list[b] == '\t')) ++b;
    while (e > b && (list[e - 1] == ' ' || list[e - 1] == '\t')) --e;
    if (e > b) out.push_back(list.substr(b, e - b));
    i = j + 1;
  }
  return out;
}

// Empty when `text` is an origin ("scheme://host[:port]", no path), else the reason.
std::string origin_problem(const std::string& text) {
  const auto sep = text.find("://");
  const bool ok = sep != std::string::npos && (text.substr(0, sep) == "http" || text.substr(0, sep) == "https") &&
                  sep + 3 < text.size() && text.find_first_of("/?# ", sep + 3) == std::string::npos;
  return ok ? std::string() : "'" + text + "' is not an origin (scheme://host[:port], no path)";
}

// Empty when `text` is a Host header value, else the reason.
std::string host_value_problem(const std::string& text) {
  const bool ok = !text.empty() && text.find_first_of("/?# @") == std::string::npos && text.find("://") == std::string::npos;
  return ok ? std::string() : "'" + text + "' is not a Host header value (name:port, e.g. bench-pc.lab:8080)";
}

// The daemon config file: every key optional, unknown keys rejected, paths relative to the file.
struct FileSettings {
  std::optional<std::string> listen, db, bench_name;
  bool allow_remote_plain_http = false;
  std::optional<std::filesystem::path> data_dir, web_dir, bench;
  std::optional<synbench::Json> twin;  // an object, or a file name resolved to its contents
  std::optional<std::filesystem::path> twin_file;
  std::vector<std::string> allow_hosts, allow_origins;
};

// Reads the whole file through the JSON reader, so one UsageError names every problem at its
// JSON pointer ("--config: FILE: /lissten: unknown field; /allow_hosts/1: must be a string").
FileSettings read_config_file(const std::filesystem::path& file, const std::string& flag) {
  // "cannot read PATH: cannot open: No such file or directory", "cannot read PATH: not valid JSON: ..."
  drivers::JsonParsed read = drivers::read_json_file(file);
  if (!read.ok()) throw UsageError(flag, "cannot read " + read.error);
  drivers::JsonReader reader;
  const drivers::JsonNode doc = drivers::read_root(read.doc, reader);
  FileSettings s;
  if (doc.object()) {
    doc.reject_unknown({"listen", "data_dir", "web_dir", "bench", "twin", "allow_hosts", "allow_origins",
                        "allow_remote_plain_http", "db", "bench_name"});
    const auto base = file.parent_path();
    const auto path = [&](std::string_view key) -> std::optional<std::filesystem::path> {
      const auto t = doc[key].text(true);
      if (!t) return std::nullopt;
      std::filesystem::path p = *t;
      return p.is_absolute() ? p : base / p;
    };
    // A list of strings, each lower-cased and checked by `problem`, reported at its own element.
    const auto strings = [&](std::string_view key, std::string (*problem)(const std::string&)) {
      std::vector<std::string> out;
      const auto items = doc[key].list("must be a list of strings");
      if (!items) return out;
      for (const auto& item : *items) {
        auto t = item.text();
        if (!t) continue;
        *t = lower(*t);
        if (auto reason = problem(*t); !reason.empty()) item.fail(std::move(reason));
        else out.push_back(std::move(*t));
      }
      return out;
    };
    s.listen = doc["listen"].text(true);
    s.allow_remote_plain_http = doc["allow_remote_plain_http"].boolean().value_or(false);
    s.data_dir = path("data_dir");
    s.web_dir = path("web_dir");
    s.bench = path("bench");
    // A database file relative to the config file, as every path in it; a PostgreSQL URL as given.
    if (auto d = doc["db"].text(true)) s.db = db::is_postgres_target(*d) ? *d : path("db")->string();
    s.bench_name = doc["bench_name"].text(true);
    if (const auto twin = doc["twin"]; twin.present()) {
      if (twin.json().is_object()) s.twin = twin.json();
      else if (twin.json().is_string()) s.twin_file = path("twin");
      else twin.fail("must be a twin config object or a file name (docs/emulator-config.md)");
    }
    s.allow_hosts = strings("allow_hosts", host_value_problem);
    s.allow_origins = strings("allow_origins", origin_problem);
  }
  if (!reader.ok()) {
    std::string all;
    for (const auto& e : reader.errors) all += (all.empty() ? "" : "; ") + drivers::to_string(e);
    throw UsageError(flag, file.string() + ": " + all);
  }
  return s;
}

}  // namespace

EnvLookup process_env() {
  return [](const std::string& name) -> std::optional<std::string> {
    const char* v = std::getenv(name.c_str());
    if (!v || !*v) return std::nullopt;
    return std::string(v);
  };
}

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

void parse_listen(const std::string& text, const std::string& what, std::string& host, std::uint16_t& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw UsageError(what, "'" + text + "' is not HOST:PORT");
  host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string p = text.substr(colon + 1);
  char* end = nullptr;
  const long v = std::strtol(p.c_str(), &end, 10);
  if (end != p.c_str() + p.size() || v < 0 || v > 65535) throw UsageError(what, "'" + p + "' is not a port (0..65535)");
  port = static_cast<std::uint16_t>(v);
}

std::string parse_origin(std::string text, const std::string& what) {
  text = lower(text);
  if (auto reason = origin_problem(text); !reason.empty()) throw UsageError(what, reason);
  return text;
}

std::string parse_host_value(std::string text, const std::string& what) {
  text = lower(text);
  if (auto reason = host_value_problem(text); !reason.empty()) throw UsageError(what, reason);
  return text;
}

ServeOptions parse_serve_options(const std::vector<std::string>& argv, const EnvLookup& env,
                                 const std::filesystem::path& default_web_dir) {
  Args a(argv, {"--help", "--allow-remote-plain-http"}, {"--listen", "--data-dir", "--config", "--twin-config", "--bench", "--web-dir", "--bench-name", "--db"},
         {"--allow-host", "--allow-origin"});
  if (!a.positional().empty()) throw UsageError(a.positional().front(), "unexpected argument");
  ServeOptions o;
  o.web_dir = default_web_dir;

  // Lowest first: the file, then the environment, then the flags.
  FileSettings file;
  if (auto f = a.text("--config")) file = read_config_file(*f, "--config");
  else if (auto e = env("SYNBENCH_CONFIG")) file = read_config_file(*e, "SYNBENCH_CONFIG");

  // One setting from its three sources: returns the value and the name of its source.
  const auto pick = [&](const std::string& flag, const std::string& var, const std::optional<std::string>& from_file)
      -> std::optional<std::pair<std::string, std::string>> {
    if (auto v = a.text(flag)) return std::make_pair(*v, flag);
    if (auto v = env(var)) return std::make_pair(*v, var);
    if (from_file) return std::make_pair(*from_file, std::string("--config"));
    return std::nullopt;
  };
  const auto opt_path = [](const std::optional<std::filesystem::path>& p) {
    return p ? std::optional<std::string>(p->string()) : std::nullopt;
  };

  std::string listen_from = "--listen";
  if (auto v = pick("--listen", "SYNBENCH_LISTEN", file.listen)) {
    parse_listen(v->first, v->second, o.listen_host, o.listen_port);
    listen_from = v->second;
  }
  o.allow_remote_plain_http = a.has("--allow-remote-plain-http") || env("SYNBENCH_ALLOW_REMOTE_PLAIN_HTTP") == "1" ||
                              file.allow_remote_plain_http;
  if (!is_loopback(o.listen_host) && !o.allow_remote_plain_http)
    throw UsageError(listen_from, "'" + o.listen_host + "' is not a loopback address: the API is plain HTTP, so bearer "
                                  "tokens would cross the network in the clear. Serve it on loopback behind a TLS "
                                  "proxy (docs/deployment.md), or confirm with --allow-remote-plain-http");
  if (auto v = pick("--data-dir", "SYNBENCH_DATA_DIR", opt_path(file.data_dir))) {
    if (v->first.empty()) throw UsageError(v->second, "needs a directory");
    o.data_dir = v->first;
  }
  if (auto v = pick("--web-dir", "SYNBENCH_WEB_DIR", opt_path(file.web_dir))) o.web_dir = v->first;
  if (auto v = pick("--bench", "SYNBENCH_BENCH", opt_path(file.bench))) o.bench = v->first;
  if (auto v = pick("--bench-name", "SYNBENCH_BENCH_NAME", file.bench_name)) o.bench_name = v->first;
  if (auto v = pick("--db", "SYNBENCH_DB", file.db)) {
    if (v->first.empty()) throw UsageError(v->second, "needs a database file or a postgresql:// URL");
    o.db = v->first;
  }

  // The twin: a file from a flag or the environment replaces the config file's twin section.
  const auto twin_from = [&](const std::string& what, const std::string& path) {
    try {
      o.twin = emulator::load_twin_config_file(path);
    } catch (const std::exception& e) {
      throw UsageError(what, e.what());
    }
  };
  if (auto f = a.text("--twin-config")) twin_from("--twin-config", *f);
  else if (auto var = env("SYNBENCH_TWIN_CONFIG")) twin_from("SYNBENCH_TWIN_CONFIG", *var);
  else if (file.twin_file) twin_from("--config: /twin", file.twin_file->string());
  else if (file.twin) {
    try {
      emulator::apply_json(o.twin, *file.twin);
      emulator::validate(o.twin);
    } catch (const std::exception& e) {
      throw UsageError("--config", std::string("/twin: ") + e.what());
    }
  }

  // Lists: flags replace the environment, which replaces the file.
  const auto list = [&](const std::string& flag, const std::string& var, const std::vector<std::string>& from_file,
                        std::string (*parse)(std::string, const std::string&)) {
    std::vector<std::string> out;
    if (!a.all(flag).empty()) {
      for (const auto& v : a.all(flag)) out.push_back(parse(v, flag));
    } else if (auto e = env(var)) {
      for (const auto& v : split_list(*e)) out.push_back(parse(v, var));
    } else {
      out = from_file;
    }
    return out;
  };
  o.allow_hosts = list("--allow-host", "SYNBENCH_ALLOW_HOSTS", file.allow_hosts, parse_host_value);
  o.allow_origins = list("--allow-origin", "SYNBENCH_ALLOW_ORIGINS", file.allow_origins, parse_origin);
  return o;
}

}  // namespace synbench::cli
