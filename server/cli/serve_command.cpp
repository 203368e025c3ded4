// `synbench serve`: the daemon. REST, WebSocket and the dashboard on one port (server/http/), the
// in-process twin (or a bench config's drives) in real time under the safety supervisor, bearer
// tokens from the data directory. SIGINT/SIGTERM
// bring the bench to its ordered stop and exit 0.
#include <sys/stat.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <functional>
#include <thread>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "db/store.hpp"
#include "drivers/utf8.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/db_log.hpp"
#include "server/cli/serve_options.hpp"
#include "server/http/api_routes.hpp"
#include "app/bench_backend.hpp"
#include "app/bench_runtime.hpp"
#include "server/http/http_server.hpp"
#include "server/http/router.hpp"
#include "server/http/sweep_routes.hpp"
#include "server/http/telemetry_routes.hpp"
#include "server/http/tokens.hpp"
#include "server/http/worker.hpp"
#include "server/http/ws_hub.hpp"
#include "synbench/version.hpp"

namespace synbench::cli {

const char* const kServeHelp = R"(usage: synbench serve [--listen HOST:PORT] [--data-dir DIR] [--config FILE]
                      [--twin-config FILE] [--bench FILE] [--bench-name NAME] [--db FILE|URL]
                      [--web-dir DIR]
                      [--allow-host NAME:PORT]... [--allow-origin ORIGIN]...

Runs the synbench daemon on one port: the REST API (docs/api.md; OpenAPI document at
/api/openapi.json, Prometheus metrics at /metrics), the WebSocket /ws (telemetry, sweep
progress, events) and the web dashboard at /. The bench is the in-process twin in real time,
or the drives of a bench config (--bench), under the safety supervisor. Prints
"listening on http://HOST:PORT" once ready.

Each setting comes from its flag, else its environment variable, else the config file, else
the default (docs/deployment.md):

  --listen HOST:PORT   SYNBENCH_LISTEN, "listen": address to listen on (default 127.0.0.1:8080;
                       port 0 picks a free one). Requests must name it in their Host header
                       (localhost equivalents are accepted for a loopback address)
  --data-dir DIR       SYNBENCH_DATA_DIR, "data_dir": the daemon's directory (default
                       ./synbench-data, created 0700): tokens.json holds the tokens' SHA-256
                       digests, synbench.db the sweeps. On first start an operator token is
                       created, printed once on stderr and written to DIR/operator.token (0600)
  --config FILE        SYNBENCH_CONFIG: the daemon config file (JSON; keys listen, data_dir,
                       twin, bench, web_dir, allow_hosts, allow_origins, db, bench_name; paths
                       relative to it)
  --twin-config FILE   SYNBENCH_TWIN_CONFIG, "twin": the twin config (docs/emulator-config.md);
                       its firmware limits also bound the setpoints with --bench
  --bench FILE         SYNBENCH_BENCH, "bench": a bench config (docs/bench-config.md): the real
                       drives over Modbus RTU/TCP, or `synbench emulate`, instead of the twin
  --db FILE|URL        SYNBENCH_DB, "db": the store instead of DIR/synbench.db: a SQLite file, or a
                       PostgreSQL lab store (postgresql://user@host:port/db, or libpq's
                       host=/socket/dir dbname=db form; docs/database.md). Its password is
                       never printed
  --bench-name NAME    SYNBENCH_BENCH_NAME, "bench_name": this bench's name, stored with every sweep next to
                       the host and the device profiles' versions (default: the host name)
  --web-dir DIR        SYNBENCH_WEB_DIR, "web_dir": the web dashboard's built files, served at /
                       (default: the source tree's web/dist)
  --allow-host NAME:PORT
                       SYNBENCH_ALLOW_HOSTS (comma-separated), "allow_hosts": a Host header value
                       accepted besides the listen address (the name a proxy or a published
                       container port is reached by); repeatable
  --allow-remote-plain-http
                       SYNBENCH_ALLOW_REMOTE_PLAIN_HTTP=1, "allow_remote_plain_http": true:
                       accept a --listen address other than loopback (plain HTTP: tokens in the
                       clear; prints a warning). Without it such an address is refused (exit 2)
  --allow-origin ORIGIN
                       SYNBENCH_ALLOW_ORIGINS (comma-separated), "allow_origins": a browser origin
                       (scheme://host[:port]) allowed to open /ws besides http:// + an allowed
                       Host; repeatable
  --help               this text

More tokens: synbench token create --role viewer|operator --data-dir DIR
exit status: 0 stopped by SIGINT/SIGTERM, 1 could not start, 2 bad input
)";

int serve_command(const std::vector<std::string>& argv) {
  for (const auto& a : argv)
    if (a == "--help") {
      std::cout << kServeHelp;
      return 0;
    }
  ServeOptions options;
  std::optional<LoadedBench> real_bench;
  try {
    options = parse_serve_options(argv, process_env(), SYNBENCH_DEFAULT_WEB_DIR);
    if (options.bench) real_bench = load_bench_or_throw(options.bench->string(), "--bench");
  } catch (const UsageError& e) {
    std::cerr << "synbench serve: " << e.what() << "\n";
    return 2;
  }
  const std::string& host = options.listen_host;
  if (!is_loopback(host))
    std::cerr << "synbench serve: WARNING: listening on " << host << " over plain HTTP (--allow-remote-plain-http): "
              << "bearer tokens cross the network in the clear; put a TLS proxy in front (docs/deployment.md)\n";
  const std::uint16_t port = options.listen_port;
  const std::filesystem::path& data_dir = options.data_dir;
  const emulator::TwinConfig& config = options.twin;

  std::error_code ec;
  std::filesystem::create_directories(data_dir, ec);
  if (ec) {
    std::cerr << "synbench serve: cannot create " << data_dir.string() << ": " << ec.message() << "\n";
    return 1;
  }
  ::chmod(data_dir.c_str(), 0700);  // the tokens' digests and the database are the operator's own
  // Everything this daemon creates is the operator's alone too: the database and its -wal and
  // -shm (SQLite creates them 0644 by default), the telemetry history. Files an earlier version
  // created are tightened as well.
  ::umask(077);
  for (const char* name : {"synbench.db", "synbench.db-wal", "synbench.db-shm", "telemetry-history.bin"})
    if (std::filesystem::exists(data_dir / name, ec)) ::chmod((data_dir / name).c_str(), 0600);
  // A data directory that held a store (its -wal or -shm, the telemetry history, tokens) but no
  // longer holds the database: a new empty store would be created without a word. Said loudly.
  if (options.db.empty() && !std::filesystem::exists(data_dir / "synbench.db", ec)) {
    std::string traces;
    for (const char* name : {"synbench.db-wal", "synbench.db-shm", "telemetry-history.bin", "tokens.json"})
      if (std::filesystem::exists(data_dir / name, ec)) traces += std::string(traces.empty() ? "" : ", ") + name;
    if (!traces.empty())
      std::cerr << "synbench serve: WARNING: " << (data_dir / "synbench.db").string()
                << " is missing, but the data directory holds an earlier store's files (" << traces
                << "): the sweeps stored there are not in the new, empty database created now. If it was moved or "
                   "deleted by mistake, stop the daemon and put it back before running anything\n";
  }

  http::TokenStore tokens(data_dir / "tokens.json");
  if (auto e = tokens.load()) {
    std::cerr << "synbench serve: " << tokens.file().string() << " is unreadable: " << tokens.load_error() << "\n";
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

  // Checked at start: damaged pages (quick_check) and a file that cannot be written are refused
  // here, not found in the middle of a sweep. Every later storage failure is logged.
  db::StoreOptions store_options;
  store_options.verify = true;
  store_options.on_error = db_error_logger("synbench serve: ");
  store_options.bench = bench_identity(real_bench, options.bench_name);
  // The lab store (PostgreSQL) when --db names one, else the data directory's SQLite file.
  const std::filesystem::path db_target = options.db.empty() ? data_dir / "synbench.db" : std::filesystem::path(options.db);
  auto store = db::Store::open(db_target, store_options);
  if (!store) {
    std::cerr << "synbench serve: cannot use the database: " << store.error().message << "\n";
    return 1;
  }
  // Sweeps a crashed process left `running` are not running: marked aborted (resumable), each
  // with its event; one that `synbench sweep` runs on this file right now is left alone.
  if (auto left = store->abort_left_running(); !left) {
    std::cerr << "synbench serve: cannot use the database: " << left.error().message << "\n";
    return 1;
  } else {
    for (const auto& l : *left) std::cerr << "synbench serve: " << l.message << "\n";
  }

  const std::string bench_what = real_bench ? "the bench of " + options.bench->string() : "the in-process twin";
  // The bench thread logs what an operator must see in the journal: faults, alarms, stops.
  const auto log = [](const app::BenchEvent& e) {
    if (e.kind == "fault" || e.kind == "alarm" || e.kind == "stop" || e.kind == "state")
      std::cerr << "synbench serve: bench " << e.kind << ": " << e.message << "\n";
  };
  app::BenchRuntime bench(make_backend(std::move(real_bench), config),
                          [](const app::BenchStatus& s) { return http::dump_json(http::status_json(s)); }, log);
  http::HttpMetrics metrics;
  http::Router router([&tokens](std::string_view t) { return tokens.authenticate(t); });
  http::ControlLock control;
  http::add_api_routes(router, {bench, config, control, metrics, synbench::kVersion});
  // Stored with every sweep created here: the twin's config, or the bench config of the drives.
  synbench::Json bench_meta = emulator::to_json(config);
  if (options.bench) {
    std::ifstream in(*options.bench);
    bench_meta = {{"bench_file", options.bench->string()},
                  {"bench", synbench::Json::parse(in, nullptr, false)},
                  {"devices", bench.devices_json()}};
  }
  // The estimate, exports and analyses on a thread of their own: the io thread stays free for
  // the E-stop.
  http::Worker worker;
  http::add_sweep_routes(router, *store, bench, control, worker, db_target, bench_meta);
  // The telemetry trace of the last run, before this one's with the down time as a gap; saved
  // every 30 s on the worker (atomically) and at the end, so a restart keeps it.
  const auto history_file = data_dir / "telemetry-history.bin";
  const auto wall_s = [] {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  if (auto e = bench.history().load(history_file, bench.snapshot()->status.t_s, wall_s()))
    std::cerr << "synbench serve: " << history_file.string() << " is unreadable (" << e.message() << "): the trace starts anew\n";
  const auto save_history = [&bench, history_file, wall_s] {
    if (auto e = bench.history().save(history_file, wall_s()))
      std::cerr << "synbench serve: cannot save " << history_file.string() << ": " << e.message() << "\n";
  };
  http::add_telemetry_routes(router, bench.history(), worker);

  boost::asio::io_context io(1);
  http::HttpServer server(io, router, http::ServerLimits{},
                          [&metrics](const std::string&, const std::string&, int status) { metrics.count(status); });
  // The dashboard's files and the WebSocket hub (telemetry, sweep, events) on the same port.
  server.set_web_dir(options.web_dir);
  server.set_extra_hosts(options.allow_hosts);
  auto hub = std::make_shared<http::WsHub>(io, bench, router, [&tokens](std::string_view t) { return tokens.authenticate(t); },
                                           synbench::kVersion);
  server.set_websocket(hub, options.allow_origins);
  // Weak: the hub's timer must not outlive the io_context declared after `metrics`.
  metrics.set_ws_source([weak = std::weak_ptr<http::WsHub>(hub)] {
    const auto h = weak.lock();
    return h ? http::WsCounts{h->session_count(), h->dropped()} : http::WsCounts{};
  });
  metrics.set_connection_source([&server] { return http::ConnectionCounts{server.connections(), server.evicted()}; });
  hub->start();
  boost::asio::steady_timer history_timer(io);
  std::function<void()> save_history_later = [&] {
    history_timer.expires_after(std::chrono::seconds(30));
    history_timer.async_wait([&](const boost::system::error_code& e) {
      if (e) return;
      worker.post(save_history);
      save_history_later();
    });
  };
  save_history_later();
  if (auto e = server.listen(host, port)) {
    std::cerr << "synbench serve: cannot listen on " << host << ":" << port << ": " << e.message() << "\n";
    return 1;
  }
  bench.start();

  // The first SIGINT/SIGTERM brings the bench to its ordered stop on a thread of its own while
  // the API still answers (an operator can still E-stop it); a second one is an E-stop.
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  std::thread stopper;
  std::function<void()> await_signal = [&] {
    signals.async_wait([&](const boost::system::error_code& e, int sig) {
      if (e) return;
      if (!stopper.joinable()) {
        std::cerr << "synbench serve: signal " << sig << ": ordered stop (another signal: E-stop)\n";
        stopper = std::thread([&] {
          bench.shutdown();
          boost::asio::post(io, [&] {
            server.close();
            history_timer.cancel();
            hub->stop();
            io.stop();
          });
        });
      } else {
        std::cerr << "synbench serve: signal " << sig << ": E-stop\n";
        bench.estop("E-stop (signal " + std::to_string(sig) + ")", {});
      }
      await_signal();
    });
  };
  await_signal();
  const bool v6 = host.find(':') != std::string::npos;
  std::cout << "listening on http://" << (v6 ? "[" + host + "]" : host) << ":" << server.port() << std::endl;
  std::cerr << "synbench serve: bench: " << bench_what << "\n";
  // The io loop outlives anything thrown inside it: every handler and session guards its own
  // work, and this is the last line, so one request can never end the daemon.
  for (;;) {
    try {
      io.run();
      break;
    } catch (const std::exception& e) {
      std::cerr << "synbench serve: the io loop caught: " << drivers::escape_invalid_utf8(e.what()) << "\n";
    } catch (...) {
      std::cerr << "synbench serve: the io loop caught an exception that is not a std::exception\n";
    }
  }
  worker.stop();  // its answers go to the io_context, which must outlive them
  if (stopper.joinable()) stopper.join();
  bench.shutdown();
  save_history();
  std::cerr << "synbench serve: stopped\n";
  return 0;
}

}  // namespace synbench::cli
