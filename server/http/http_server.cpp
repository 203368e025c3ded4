// Listener and sessions; see http_server.hpp.
#include "server/http/http_server.hpp"

#include <array>
#include <chrono>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

#include "drivers/utf8.hpp"
#include "server/http/connection_registry.hpp"
#include "server/http/sign_in_log.hpp"
#include "server/http/static_files.hpp"
#include "server/http/url_text.hpp"
#include "server/http/ws_hub.hpp"
#include "server/http/ws_session.hpp"

namespace synbench::http {

namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

std::set<std::string> allowed_hosts(const std::string& listen_host, std::uint16_t port) {
  const std::string p = ":" + std::to_string(port);
  std::set<std::string> out;
  boost::system::error_code ec;
  const auto addr = net::ip::make_address(listen_host, ec);
  // 0.0.0.0 or :: names no host a client can reach: the names come from --allow-host.
  if (!ec && addr.is_unspecified()) return out;
  const bool v6 = listen_host.find(':') != std::string::npos;
  out.insert((v6 ? "[" + listen_host + "]" : listen_host) + p);
  if (listen_host == "localhost" || (!ec && addr.is_loopback()))
    for (const char* h : {"localhost", "127.0.0.1", "[::1]"}) out.insert(std::string(h) + p);
  return out;
}

std::set<std::string> allowed_origins(const std::set<std::string>& hosts, const std::vector<std::string>& extra) {
  std::set<std::string> out;
  for (const auto& h : hosts) out.insert("http://" + ascii_lower(h));
  for (const auto& o : extra) out.insert(ascii_lower(o));
  return out;
}

struct HttpServer::Shared {
  Shared(const Router& r, ServerLimits l, Observer o) : router(r), limits(l), observer(std::move(o)) {}
  const Router& router;
  ServerLimits limits;
  Observer observer;
  std::set<std::string> hosts;
  std::optional<StaticFiles> files;
  std::shared_ptr<WsHub> hub;
  std::vector<std::string> extra_origins;
  std::vector<std::string> extra_hosts;
  std::set<std::string> origins;
  std::atomic<bool> closing{false};
  std::shared_ptr<ConnectionRegistry> registry = std::make_shared<ConnectionRegistry>();
};

namespace {

void fail(beast::error_code ec, const char* what) {
  // Ordinary ends of a connection are not worth a line.
  if (ec == net::error::operation_aborted || ec == bhttp::error::end_of_stream || ec == beast::error::timeout ||
      ec == net::error::eof || ec == net::error::connection_reset)
    return;
  std::cerr << "synbench serve: " << what << ": " << ec.message() << "\n";
}

// The REST router's share of the paths; everything else but /ws is the dashboard's.
bool routed(const std::string& path) {
  return path == "/api" || path.rfind("/api/", 0) == 0 || path == "/metrics";
}

Trust trust_of(const std::optional<Identity>& who) {
  if (!who) return Trust::none;
  return who->role == Role::operator_ ? Trust::operator_ : who->role == Role::viewer ? Trust::viewer : Trust::none;
}

// A request whose framing or identity is ambiguous: answered (400, or 501 for a transfer coding
// we do not implement) and the connection closed, since its body can not be told from the next
// request. RFC 9112 Sec. 6.1 and 6.3: a transfer coding other than a final "chunked", or one on
// an HTTP/1.0 request; Sec. 3.2: more than one Host. More than one Authorization is refused too:
// which of them the daemon acted on must never be a guess.
struct FramingProblem {
  int status;
  std::string message;
};

std::optional<FramingProblem> framing_problem(const bhttp::request_header<>& h) {
  if (h.count(bhttp::field::host) > 1) return FramingProblem{400, "more than one Host header"};
  if (h.count(bhttp::field::authorization) > 1) return FramingProblem{400, "more than one Authorization header"};
  if (!h.count(bhttp::field::transfer_encoding)) return std::nullopt;
  if (h.version() < 11) return FramingProblem{400, "Transfer-Encoding in an HTTP/1.0 request (RFC 9112 Sec. 6.1)"};
  if (h.count(bhttp::field::content_length))
    return FramingProblem{400, "both Transfer-Encoding and Content-Length (RFC 9112 Sec. 6.1)"};
  std::vector<std::string> codings;
  const auto [first, last] = h.equal_range(bhttp::field::transfer_encoding);
  for (auto f = first; f != last; ++f) {
    const std::string v(f->value());
    std::size_t start = 0;
    while (start <= v.size()) {
      std::size_t end = v.find(',', start);
      if (end == std::string::npos) end = v.size();
      std::string c = v.substr(start, end - start);
      c = c.substr(0, c.find(';'));
      const auto b = c.find_first_not_of(" \t"), e = c.find_last_not_of(" \t");
      if (b != std::string::npos) codings.push_back(ascii_lower(c.substr(b, e - b + 1)));
      start = end + 1;
    }
  }
  if (codings.empty() || codings.back() != "chunked")
    return FramingProblem{400, "Transfer-Encoding must end in chunked (RFC 9112 Sec. 6.3)"};
  if (codings.size() > 1)
    return FramingProblem{501, "transfer coding '" + codings.front() + "' is not implemented (only chunked is)"};
  return std::nullopt;
}

class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket&& socket, std::shared_ptr<HttpServer::Shared> shared)
      : stream_(std::move(socket)), shared_(std::move(shared)) {}

  // Registers the connection (its client's address) and starts reading.
  void run(const std::string& client) {
    client_ = client;
    const auto id = shared_->registry->add(client, [weak = weak_from_this(), ex = stream_.get_executor()] {
      net::post(ex, [weak] {
        if (auto self = weak.lock()) self->evict();
      });
    });
    slot_ = std::make_shared<ConnectionSlot>(shared_->registry, id);
    net::dispatch(stream_.get_executor(), beast::bind_front_handler(&Session::do_read, shared_from_this()));
  }

  // Over the connection limit: one 503 and close, without reading a request.
  void refuse() {
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] {
      self->send_error(503, "too_many_connections",
                       "more than " + std::to_string(self->shared_->limits.max_connections) + " open connections", false);
    });
  }

 private:
  // Made room for another connection: the read in flight ends with operation_aborted.
  void evict() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.socket().close(ec);
  }

  void do_read() {
    parser_.emplace();
    parser_->body_limit(shared_->limits.max_body_bytes);
    parser_->header_limit(static_cast<std::uint32_t>(shared_->limits.max_header_bytes));
    // A peer that has never shown a token gets little time: trickling bytes buys it nothing.
    const double timeout_s = trust_ == Trust::none ? shared_->limits.unauthenticated_timeout_s : shared_->limits.read_timeout_s;
    stream_.expires_after(std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
    // The header section first: its framing is checked before a byte of the body is read, and
    // it is kept, so that chunked trailer fields never act as headers.
    bhttp::async_read_header(stream_, buffer_, *parser_, beast::bind_front_handler(&Session::on_header, shared_from_this()));
  }

  void on_header(beast::error_code ec, std::size_t n) {
    if (ec) return on_read(ec, n);
    if (const auto bad = framing_problem(parser_->get()))
      return send_error(bad->status, bad->status == 501 ? "not_implemented" : "bad_request", bad->message, false);
    // Only a chunked body can carry trailer fields: only then is the header section kept apart.
    header_kept_ = parser_->chunked();
    if (header_kept_) header_ = parser_->get().base();
    if (parser_->is_done()) return on_read({}, 0);
    bhttp::async_read(stream_, buffer_, *parser_, beast::bind_front_handler(&Session::on_read, shared_from_this()));
  }

  void on_read(beast::error_code ec, std::size_t) {
    if (ec == bhttp::error::body_limit) {
      return send_error(413, "body_too_large", "the body exceeds " + std::to_string(shared_->limits.max_body_bytes) + " bytes", false);
    }
    if (ec == bhttp::error::header_limit) {
      return send_error(431, "header_too_large", "the header exceeds " + std::to_string(shared_->limits.max_header_bytes) + " bytes", false);
    }
    if (ec == bhttp::error::end_of_stream || ec == beast::error::timeout) return do_close();
    if (ec) {
      // A malformed request gets an answer when the peer is still there to read it.
      if (ec.category() == bhttp::make_error_code(bhttp::error::bad_target).category())
        return send_error(400, "bad_request", "malformed HTTP request: " + ec.message(), false);
      return fail(ec, "read");
    }
    // Nothing thrown while answering may reach io.run(): it would end the daemon for every
    // client. The request is answered 500 and the line on stderr says what was caught.
    try {
      auto req = parser_->release();
      if (header_kept_) req.base() = std::move(header_);  // the header section only: trailer fields are dropped
      handle(std::move(req));
    } catch (const std::exception& e) {
      std::cerr << "synbench serve: internal error answering a request: " << drivers::escape_invalid_utf8(e.what()) << "\n";
      send_error(500, "internal", "the request failed inside the daemon", false);
    }
  }

  void handle(bhttp::request<bhttp::string_body> req) {
    const bool keep_alive = req.keep_alive() && !shared_->closing;
    // The connection's trust (whom eviction spares) from its token: the same header as this
    // connection's last request needs no second digest (the router still checks every request).
    if (const auto a = req[bhttp::field::authorization];
        req.count(bhttp::field::authorization) && (trusted_authorization_.empty() || std::string_view(a.data(), a.size()) != trusted_authorization_)) {
      const auto who = shared_->router.identify(std::string_view(a.data(), a.size()));
      if (who) trusted_authorization_.assign(a.data(), a.size());
      if (!who) log_failed_sign_in(client_, std::string(req.method_string()) + " " + std::string(req.target().substr(0, 80)));
      const Trust t = trust_of(who);
      if (static_cast<int>(t) > static_cast<int>(trust_)) {
        trust_ = t;
        slot_->trust(t);
      }
    }
    const std::string host(req[bhttp::field::host]);
    const std::string method(req.method_string());
    const std::string target(req.target());
    const std::string path = target.substr(0, target.find('?'));
    Response r;
    if (!shared_->hosts.count(ascii_lower(host))) {
      r = error_response(403, "host_not_allowed", "the Host header must name the listen address");
    } else if (path == "/ws" && shared_->hub) {
      const std::string origin(req[bhttp::field::origin]);
      if (!beast::websocket::is_upgrade(req)) {
        r = error_response(426, "upgrade_required", "/ws is a WebSocket endpoint (docs/api.md)");
        r.headers.emplace_back("Upgrade", "websocket");
      } else if (req.count(bhttp::field::origin) && !shared_->origins.count(ascii_lower(origin))) {
        // A browser always sends Origin: a page from another site must not reach the bench with
        // a token it got hold of. Clients that are not browsers send none.
        r = error_response(403, "origin_not_allowed", "the Origin header is not an allowed origin (see --allow-origin)");
      } else {
        if (shared_->observer) shared_->observer(method, path, 101);
        return upgrade(std::move(req));
      }
    } else if (routed(path) || !shared_->files) {
      const auto auth = req[bhttp::field::authorization];
      // A bench command answers from the bench thread once it has acted: the answer comes back
      // to this session's strand, and the io thread serves others meanwhile.
      // A route that answers at once (most) is answered right here, without a second trip
      // through the io loop; only an answer from another thread is posted back to the strand.
      const Meta meta{method, path, req.version(), keep_alive, req.method() == bhttp::verb::head};
      const std::uint64_t seq = ++dispatch_seq_;
      dispatching_ = seq;
      shared_->router.dispatch_async(method, target, std::string_view(auth.data(), auth.size()), std::move(req.body()),
                                     [self = shared_from_this(), meta, seq, here = std::this_thread::get_id()](Response answer) {
                                       if (std::this_thread::get_id() == here && self->dispatching_ == seq) {
                                         self->sync_answer_ = std::move(answer);
                                         return;
                                       }
                                       net::post(self->stream_.get_executor(), [self, meta, answer = std::move(answer)]() mutable {
                                         self->respond(meta, std::move(answer));
                                       });
                                     });
      dispatching_ = 0;
      if (sync_answer_) {
        Response answer = std::move(*sync_answer_);
        sync_answer_.reset();
        respond(meta, std::move(answer));
      }
      return;
    } else {
      // The dashboard's files need no token: the page signs in itself.
      const auto inm = req[bhttp::field::if_none_match];
      const auto ae = req[bhttp::field::accept_encoding];
      r = shared_->files->serve(method, target, std::string_view(inm.data(), inm.size()), std::string_view(ae.data(), ae.size()));
    }
    respond({method, path, req.version(), keep_alive, req.method() == bhttp::verb::head}, std::move(r));
  }

  // What the answer to a request needs to know of it.
  struct Meta {
    std::string method, path;
    unsigned version;
    bool keep_alive, head;
  };

  void respond(const Meta& m, Response r) {
    if (shared_->observer) shared_->observer(m.method, m.path, r.status);
    auto res = std::make_shared<bhttp::response<bhttp::string_body>>(static_cast<bhttp::status>(r.status), m.version);
    res->set(bhttp::field::server, "synbench");
    res->set(bhttp::field::content_type, r.content_type);
    res->set(bhttp::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    for (const auto& [k, v] : r.headers) res->set(k, v);
    res->keep_alive(m.keep_alive);
    res->body() = std::move(r.body);
    res->prepare_payload();
    if (m.head) res->body().clear();  // Content-Length stays that of GET
    write(res);
  }

  // The connection leaves this session for a WebSocket session, which answers 101 itself.
  void upgrade(bhttp::request<bhttp::string_body> req) {
    std::make_shared<WsSession>(stream_.release_socket(), shared_->hub, std::move(slot_))->run(std::move(req));
  }

  void send_error(int status, const std::string& code, const std::string& message, bool keep_alive) {
    draining_ = !keep_alive;
    Response r = error_response(status, code, message);
    if (shared_->observer) shared_->observer("?", "?", status);
    auto res = std::make_shared<bhttp::response<bhttp::string_body>>(static_cast<bhttp::status>(status), 11);
    res->set(bhttp::field::server, "synbench");
    res->set(bhttp::field::content_type, r.content_type);
    res->keep_alive(keep_alive);
    res->body() = std::move(r.body);
    res->prepare_payload();
    write(res);
  }

  void write(std::shared_ptr<bhttp::response<bhttp::string_body>> res) {
    stream_.expires_after(std::chrono::milliseconds(static_cast<long>(shared_->limits.read_timeout_s * 1000)));
    bhttp::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec) return fail(ec, "write");
      if (!res->keep_alive()) return self->do_close();
      self->do_read();
    });
  }

  void do_close() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
    if (draining_) drain();
  }

  // After refusing a request whose body we did not read, read and discard what the peer still
  // sends (bounded, 2 s) before closing: closing with unread data resets the connection, and a
  // reset can destroy our error response in the peer's buffer before the peer reads it.
  void drain() {
    stream_.expires_after(std::chrono::seconds(2));
    stream_.async_read_some(net::buffer(discard_), [self = shared_from_this()](beast::error_code ec, std::size_t n) {
      self->drained_ += n;
      if (!ec && self->drained_ < (1u << 20)) self->drain();
    });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  bhttp::request_header<> header_;  // a chunked request's header section, as read before its body
  bool header_kept_ = false;
  std::shared_ptr<HttpServer::Shared> shared_;
  std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
  std::shared_ptr<ConnectionSlot> slot_;  // empty for a connection refused at the door
  Trust trust_ = Trust::none;
  std::string trusted_authorization_;  // the last Authorization header that identified a caller
  // The dispatch under way on this thread (0: none), and its answer when the route gave it
  // before dispatch_async returned.
  std::uint64_t dispatch_seq_ = 0, dispatching_ = 0;
  std::optional<Response> sync_answer_;
  std::string client_;  // the peer's address
  bool draining_ = false;
  std::size_t drained_ = 0;
  std::array<char, 16384> discard_{};
};

}  // namespace

class HttpServer::Listener : public std::enable_shared_from_this<HttpServer::Listener> {
 public:
  Listener(net::io_context& io, std::shared_ptr<Shared> shared) : io_(io), acceptor_(net::make_strand(io)), shared_(std::move(shared)) {}

  std::error_code open(const tcp::endpoint& ep) {
    beast::error_code ec;
    acceptor_.open(ep.protocol(), ec);
    if (!ec) acceptor_.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(ep, ec);
    if (!ec) acceptor_.listen(net::socket_base::max_listen_connections, ec);
    // Non-blocking, so that on_accept can take what else is pending without waiting.
    if (!ec) acceptor_.non_blocking(true, ec);
    return ec;
  }
  std::uint16_t port() const { return acceptor_.local_endpoint().port(); }
  void run() { do_accept(); }
  void close() {
    net::post(acceptor_.get_executor(), [self = shared_from_this()] {
      beast::error_code ec;
      self->acceptor_.close(ec);
    });
  }

 private:
  void do_accept() {
    acceptor_.async_accept(net::make_strand(io_), beast::bind_front_handler(&Listener::on_accept, shared_from_this()));
  }
  void on_accept(beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (ec == net::error::operation_aborted) return;
      fail(ec, "accept");
    } else {
      admit(std::move(socket));
      // Under a flood of connections the backlog is long: taken one per handler, every open
      // connection's work runs between two accepts, and a newcomer (an operator's E-stop) waits
      // behind all of them. What else is pending is taken now, up to kAcceptBurst.
      for (int i = 0; i < kAcceptBurst && acceptor_.is_open(); ++i) {
        beast::error_code more;
        tcp::socket next(net::make_strand(io_));
        acceptor_.accept(next, more);  // would_block once none is pending
        if (more) break;
        admit(std::move(next));
      }
    }
    if (acceptor_.is_open()) do_accept();
  }

  void admit(tcp::socket socket) {
    beast::error_code ep;
    const auto remote = socket.remote_endpoint(ep);
    const std::string client = ep ? std::string("?") : remote.address().to_string();
    const bool room = shared_->registry->make_room(client, shared_->limits.max_connections,
                                                   shared_->limits.max_connections_per_client,
                                                   shared_->limits.max_untrusted_connections);
    auto session = std::make_shared<Session>(std::move(socket), shared_);
    if (room) session->run(client);
    else session->refuse();
  }

  static constexpr int kAcceptBurst = 32;

  net::io_context& io_;
  tcp::acceptor acceptor_;
  std::shared_ptr<Shared> shared_;
};

HttpServer::HttpServer(net::io_context& io, const Router& router, ServerLimits limits, Observer observer)
    : io_(io), shared_(std::make_shared<Shared>(router, limits, std::move(observer))) {}

HttpServer::~HttpServer() = default;

std::error_code HttpServer::listen(const std::string& host, std::uint16_t port) {
  boost::system::error_code ec;
  net::ip::address addr;
  if (host == "localhost") addr = net::ip::make_address("127.0.0.1");
  else addr = net::ip::make_address(host, ec);
  if (ec) return std::make_error_code(std::errc::invalid_argument);
  listener_ = std::make_shared<Listener>(io_, shared_);
  if (auto e = listener_->open(tcp::endpoint(addr, port))) return e;
  port_ = listener_->port();
  shared_->hosts = allowed_hosts(host, port_);
  shared_->hosts.insert(shared_->extra_hosts.begin(), shared_->extra_hosts.end());
  shared_->origins = allowed_origins(shared_->hosts, shared_->extra_origins);
  listener_->run();
  return {};
}

void HttpServer::set_extra_hosts(std::vector<std::string> hosts) {
  for (auto& h : hosts) h = ascii_lower(h);
  shared_->extra_hosts = std::move(hosts);
}

void HttpServer::set_web_dir(std::filesystem::path dir) { shared_->files.emplace(std::move(dir)); }

void HttpServer::set_websocket(std::shared_ptr<WsHub> hub, std::vector<std::string> extra_origins) {
  shared_->hub = std::move(hub);
  shared_->extra_origins = std::move(extra_origins);
}

std::size_t HttpServer::connections() const { return shared_->registry->size(); }
std::uint64_t HttpServer::evicted() const { return shared_->registry->evicted(); }

void HttpServer::close() {
  shared_->closing = true;
  if (listener_) listener_->close();
}

}  // namespace synbench::http
