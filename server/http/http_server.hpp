// The daemon's HTTP/1.1 server on Boost.Beast, after Beast's chat-multi example: a listener
// accepting on one io_context thread and one session per connection, reading one request,
// answering it, then reading the next (keep-alive), so at most one write is in flight per
// session. /api/... and /metrics go to the Router, an upgrade on /ws becomes a WsSession of the
// hub (ws_session.hpp), any other path is a file of the dashboard (static_files.hpp). Limits:
// header and body size (431, 413), a read/idle timeout, and the Host header must name the
// listen address (a DNS-rebinding defence) or the request gets 403; a WebSocket upgrade must
// also come from an allowed Origin (a cross-site WebSocket hijacking defence), else 403.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "server/http/router.hpp"

namespace synbench::http {

struct ServerLimits {
  std::size_t max_body_bytes = 64 * 1024;
  std::size_t max_header_bytes = 8 * 1024;
  double read_timeout_s = 15;  // for one whole request, and for idling between requests
  // Until a connection has shown a valid token: a slow or silent peer is cut this soon.
  double unauthenticated_timeout_s = 5;
  // Beyond either, the oldest least trusted connection below an operator's is closed to make
  // room (connection_registry.hpp); only when operators hold them all is the new one refused.
  // Dashboards, Prometheus and scripts poll together, behind a reverse proxy all from one
  // address: 64 connections from one client fit without an eviction.
  std::size_t max_connections = 256;
  std::size_t max_connections_per_client = 192;  // one client address's share
  // Connections that have not shown a valid token (each new one among them): a flood of them
  // churns within this many, as the whole house did when it held 64, and costs an operator's
  // new connection no more wait in the accept queue than it did then.
  std::size_t max_untrusted_connections = 64;
};

// Host header values accepted for a server listening on host:port: "host:port", and for a
// loopback address also "localhost:port", "127.0.0.1:port" and "[::1]:port".
std::set<std::string> allowed_hosts(const std::string& listen_host, std::uint16_t port);
// Origin header values accepted on a WebSocket upgrade: "http://" + each allowed host, and
// `extra` (--allow-origin), all lower case.
std::set<std::string> allowed_origins(const std::set<std::string>& hosts, const std::vector<std::string>& extra);

class WsHub;

class HttpServer {
 public:
  // Called for each answered request: method, path (no query), status. For metrics and logs;
  // never sees headers, so never a token.
  using Observer = std::function<void(const std::string& method, const std::string& path, int status)>;

  HttpServer(boost::asio::io_context& io, const Router& router, ServerLimits limits, Observer observer = {});
  ~HttpServer();
  // Binds and listens; port 0 picks a free one (see port()).
  std::error_code listen(const std::string& host, std::uint16_t port);
  // Before listen(): Host header values accepted besides the listen address's (--allow-host:
  // the name a reverse proxy or a container's published port is reached by); their http://
  // origins are then allowed on /ws too.
  void set_extra_hosts(std::vector<std::string> hosts);
  // Before listen(): the dashboard's built files, served for paths outside /api, /ws, /metrics
  // (without a call, those paths are 404).
  void set_web_dir(std::filesystem::path dir);
  // Before listen(): /ws upgrades join `hub`; browsers' Origin must be an allowed host's or one
  // of `extra_origins` (without a call, /ws is 404).
  void set_websocket(std::shared_ptr<WsHub> hub, std::vector<std::string> extra_origins);
  std::uint16_t port() const { return port_; }
  // Open connections, and how many were closed to make room for others.
  std::size_t connections() const;
  std::uint64_t evicted() const;
  // Stops accepting; open sessions end after their current request.
  void close();

  struct Shared;  // state every session shares (router, limits, allowed hosts, files, hub)

 private:
  class Listener;
  boost::asio::io_context& io_;
  std::shared_ptr<Shared> shared_;
  std::shared_ptr<Listener> listener_;
  std::uint16_t port_ = 0;
};

}  // namespace synbench::http
