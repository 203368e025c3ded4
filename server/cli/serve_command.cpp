// `synbench serve`: the daemon. REST on one port (server/http/), the in-process twin running in
// real time under the safety supervisor, bearer tokens from the data directory. SIGINT/SIGTERM
// bring the bench to its ordered stop and exit 0.
#include <sys/stat.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <filesystem>
#include <iostream>

#include "db/store.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/commands.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/bench_runtime.hpp"
#include "server/http/http_server.hpp"
#include "server/http/router.hpp"
#include "server/http/sweep_routes.hpp"
#include "server/http/tokens.hpp"
#include "synbench/version.hpp"

namespace synbench::cli {

const char* const kServeHelp = R"(usage: synbench serve [--listen HOST:PORT] [--data-dir DIR] [--config FILE]

Runs the synbench daemon: the REST API (docs/api.md; OpenAPI document at /api/openapi.json,
Prometheus metrics at /metrics) over the bench's twin, in-process and in real time, under the
safety supervisor. Prints "listening on http://HOST:PORT" once ready.

  --listen HOST:PORT   address to listen on (default 127.0.0.1:8080; port 0 picks a free one).
                       Requests must name it in their Host header (localhost equivalents are
                       accepted for a loopback address)
  --data-dir DIR       the daemon's directory (default ./synbench-data, created 0700): tokens.json
                       holds the tokens' SHA-256 digests, synbench.db the sweeps (add some
                       with `synbench sweep PLAN --db DIR/synbench.db`). On first start an
                       operator token is created, printed once on stderr and written to
                       DIR/operator.token (0600)
  --config FILE        twin config JSON (docs/emulator-config.md)
  --help               this text

More tokens: synbench token create --role viewer|operator --data-dir DIR
exit status: 0 stopped by SIGINT/SIGTERM, 1 could not start, 2 bad input
)";

namespace {

void parse_listen(const std::string& text, std::string& host, std::uint16_t& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw UsageError("--listen", "'" + text + "' is not HOST:PORT");
  host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string p = text.substr(colon + 1);
  char* end = nullptr;
  const long v = std::strtol(p.c_str(), &end, 10);
  if (end != p.c_str() + p.size() || v < 0 || v > 65535) throw UsageError("--listen", "'" + p + "' is not a port (0..65535)");
  port = static_cast<std::uint16_t>(v);
}

}  // namespace

int serve_command(const std::vector<std::string>& argv) {
  std::string host = "127.0.0.1";
  std::uint16_t port = 8080;
  std::filesystem::path data_dir = "synbench-data";
  emulator::TwinConfig config;
  try {
    Args a(argv, {"--help"}, {"--listen", "--data-dir", "--config"});
    if (a.has("--help")) {
      std::cout << kServeHelp;
      return 0;
    }
    if (!a.positional().empty()) throw UsageError(a.positional().front(), "unexpected argument");
    if (auto l = a.text("--listen")) parse_listen(*l, host, port);
    if (auto d = a.text("--data-dir")) {
      if (d->empty()) throw UsageError("--data-dir", "needs a directory");
      data_dir = *d;
    }
    if (auto file = a.text("--config")) config = emulator::load_twin_config_file(*file);
  } catch (const UsageError& e) {
    std::cerr << "synbench serve: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "synbench serve: --config: " << e.what() << "\n";
    return 2;
  }

  std::error_code ec;
  std::filesystem::create_directories(data_dir, ec);
  if (ec) {
    std::cerr << "synbench serve: cannot create " << data_dir.string() << ": " << ec.message() << "\n";
    return 1;
  }
  ::chmod(data_dir.c_str(), 0700);  // the tokens' digests and the database are the operator's own

  http::TokenStore tokens(data_dir / "tokens.json");
  if (auto e = tokens.load()) {
    std::cerr << "synbench serve: " << tokens.file().string() << " is unreadable: " << e.message() << "\n";
    return 1;
  }
  if (tokens.empty()) {
    const std::string token = tokens.create(http::Role::operator_, ec);
    const auto token_file = data_dir / "operator.token";
    if (!ec) ec = http::write_private_file(token_file, token + "\n");
    if (ec) {
      std::cerr << "synbench serve: cannot write the first operator token: " << ec.message() << "\n";
      return 1;
    }
    // The one time the daemon shows a token.
    std::cerr << "synbench serve: first start: operator token " << token << " (also in " << token_file.string()
              << ", mode 0600; more with `synbench token create`)\n";
  }

  auto store = db::Store::open(data_dir / "synbench.db");
  if (!store) {
    std::cerr << "synbench serve: cannot open " << (data_dir / "synbench.db").string() << ": " << store.error().message << "\n";
    return 1;
  }

  http::BenchRuntime bench(config, bench::SafetyLimits{});
  http::HttpMetrics metrics;
  http::Router router([&tokens](std::string_view t) { return tokens.authenticate(t); });
  http::ControlLock control;
  http::add_api_routes(router, {bench, control, metrics, synbench::kVersion});
  http::add_sweep_routes(router, *store, bench, control, data_dir / "synbench.db", nlohmann::ordered_json::parse(emulator::to_json(config).dump()));

  boost::asio::io_context io(1);
  http::HttpServer server(io, router, http::ServerLimits{},
                          [&metrics](const std::string&, const std::string&, int status) { metrics.count(status); });
  if (auto e = server.listen(host, port)) {
    std::cerr << "synbench serve: cannot listen on " << host << ":" << port << ": " << e.message() << "\n";
    return 1;
  }
  bench.start();

  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code& e, int sig) {
    if (e) return;
    std::cerr << "synbench serve: signal " << sig << ": ordered stop\n";
    server.close();
    bench.shutdown();
    io.stop();
  });
  const bool v6 = host.find(':') != std::string::npos;
  std::cout << "listening on http://" << (v6 ? "[" + host + "]" : host) << ":" << server.port() << std::endl;
  io.run();
  bench.shutdown();
  std::cerr << "synbench serve: stopped\n";
  return 0;
}

}  // namespace synbench::cli
