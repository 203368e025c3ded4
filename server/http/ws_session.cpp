// One /ws session: the protocol and the bounded write queue; see ws_session.hpp, docs/api.md.
#include "server/http/ws_session.hpp"

#include "server/http/instance_id.hpp"
#include "server/http/sign_in_log.hpp"

#include <cmath>
#include <iostream>
#include <set>

#include <boost/asio/post.hpp>

#include "drivers/json_file.hpp"
#include "drivers/profile/number_format.hpp"
#include "drivers/utf8.hpp"
#include "server/http/api_routes.hpp"

namespace synbench::http {

namespace beast = boost::beast;
namespace websocket = boost::beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

void fail(beast::error_code ec, const char* what) {
  // Ordinary ends of a connection are not worth a line.
  if (ec == net::error::operation_aborted || ec == websocket::error::closed || ec == beast::error::timeout ||
      ec == net::error::eof || ec == net::error::connection_reset || ec == net::error::broken_pipe ||
      ec == websocket::error::message_too_big)  // Beast has answered it with close 1009
    return;
  std::cerr << "synbench serve: websocket " << what << ": " << ec.message() << "\n";
}

const std::set<std::string> kChannels = {"telemetry", "sweep", "events"};

// The first field of `doc` not in `known`, as "<field>: unknown field (expected: ...)".
std::optional<std::string> unknown_field(const synbench::Json& doc, const std::set<std::string>& known) {
  for (const auto& [k, v] : doc.items())
    if (!known.count(k)) {
      std::string list;
      for (const auto& n : known) list += (list.empty() ? "" : ", ") + n;
      return k + ": unknown field (expected: " + list + ")";
    }
  return std::nullopt;
}

}  // namespace

WsSession::WsSession(tcp::socket&& socket, std::shared_ptr<WsHub> hub, std::shared_ptr<ConnectionSlot> slot)
    : ws_(std::move(socket)), hub_(std::move(hub)), slot_(std::move(slot)), auth_timer_(ws_.get_executor()) {}

WsSession::~WsSession() {
  if (joined_) hub_->leave(this);
}

void WsSession::run(beast::http::request<beast::http::string_body> req) {
  const WsLimits& lim = hub_->limits();
  auto& sock = beast::get_lowest_layer(ws_).socket();
  beast::error_code ec;
  sock.set_option(tcp::no_delay(true), ec);  // a telemetry frame goes out now, not after an ACK
  sock.set_option(net::socket_base::send_buffer_size(lim.socket_send_buffer_bytes), ec);
  if (slot_)
    slot_->set_closer([weak = weak_from_this(), ex = ws_.get_executor()] {
      net::post(ex, [weak] {
        if (auto self = weak.lock()) self->evict();
      });
    });
  auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
  timeouts.keep_alive_pings = true;  // a silent peer is pinged; one that never answers is closed
  // The closing handshake of a refused peer that does not read must not hold its slot for long.
  timeouts.handshake_timeout = lim.auth_timeout;
  ws_.set_option(timeouts);
  websocket::permessage_deflate pmd;
  pmd.server_enable = false;
  pmd.client_enable = false;
  ws_.set_option(pmd);
  ws_.read_message_max(lim.max_message_bytes);
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) { res.set(beast::http::field::server, "synbench"); }));
  ws_.async_accept(req, beast::bind_front_handler(&WsSession::on_accept, shared_from_this()));
}

void WsSession::on_accept(beast::error_code ec) {
  if (ec) return fail(ec, "accept");
  ws_.text(true);
  hub_->join(shared_from_this());
  joined_ = true;
  auth_timer_.expires_after(hub_->limits().auth_timeout);
  auth_timer_.async_wait(beast::bind_front_handler(&WsSession::on_auth_timeout, shared_from_this()));
  do_read();
}

void WsSession::on_auth_timeout(beast::error_code ec) {
  if (ec || identity_ || closing_ || dropped_) return;
  refuse("no auth message within " + std::to_string(hub_->limits().auth_timeout.count() / 1000) + " s");
}

void WsSession::do_read() {
  ws_.async_read(buffer_, beast::bind_front_handler(&WsSession::on_read, shared_from_this()));
}

void WsSession::on_read(beast::error_code ec, std::size_t) {
  if (ec) return fail(ec, "read");
  std::string text = beast::buffers_to_string(buffer_.data());
  buffer_.consume(buffer_.size());
  // Once a close is planned, what the peer still sends is read (to see its close frame) and
  // ignored.
  if (!closing_ && !dropped_) {
    if (!ws_.got_text()) {
      if (!identity_) refuse("the first message must be a text frame {\"op\":\"auth\",\"token\":...}");
      else bad_message("message: binary frames are not accepted; send JSON text");
    } else {
      // An exception must not leave this handler: it would end the io loop for every client.
      try {
        handle(text);
      } catch (const std::exception& e) {
        std::cerr << "synbench serve: websocket message failed: " << drivers::escape_invalid_utf8(e.what()) << "\n";
        bad_message("message: the daemon failed to handle it (" + drivers::escape_invalid_utf8(e.what()) + ")");
      }
    }
  }
  if (dropped_) return;
  if (requests_in_flight_ >= hub_->limits().max_requests_in_flight) read_paused_ = true;
  else do_read();
}

void WsSession::reply_done() {
  if (requests_in_flight_ > 0) --requests_in_flight_;
  if (read_paused_ && !dropped_ && requests_in_flight_ < hub_->limits().max_requests_in_flight) {
    read_paused_ = false;
    do_read();
  }
}

void WsSession::handle(const std::string& text) {
  // The shared reader: bytes that are not UTF-8, deep nesting and overflowing numbers are a
  // reason ("not valid UTF-8 at byte 3"), never an exception.
  drivers::JsonParsed parsed = drivers::parse_json_text(text);
  const std::string parse_error = parsed.error;
  const synbench::Json& doc = parsed.doc;
  std::string op;
  if (parse_error.empty() && doc.is_object() && doc.contains("op") && doc["op"].is_string()) op = doc["op"].get<std::string>();

  if (!identity_) {
    if (op != "auth") return refuse("the first message must be {\"op\":\"auth\",\"token\":...}");
    return handle_auth(doc);
  }
  if (!parse_error.empty()) return bad_message("message: " + parse_error);
  if (!doc.is_object()) return bad_message("message: must be a JSON object");
  if (!doc.contains("op")) return bad_message("op: required");
  if (op.empty()) return bad_message("op: must be a non-empty string");
  if (op == "subscribe") return handle_subscribe(doc, true);
  if (op == "unsubscribe") return handle_subscribe(doc, false);
  if (op == "request") return handle_request(doc);
  if (op == "auth") return bad_message("op: this connection is already authenticated");
  bad_message("op: unknown op '" + op + "' (expected: subscribe, unsubscribe, request)");
}

void WsSession::handle_auth(const synbench::Json& doc) {
  if (auto bad = unknown_field(doc, {"op", "token"})) return refuse(*bad);
  if (!doc.contains("token") || !doc["token"].is_string()) return refuse("token: required, a string");
  const std::string token = doc["token"].get<std::string>();
  auto who = hub_->authenticate(token);
  if (!who) {
    beast::error_code ec;
    const auto peer = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    log_failed_sign_in(ec ? std::string("?") : peer.address().to_string(), "/ws auth");
    return refuse("token: not valid");
  }
  identity_ = std::move(who);
  token_ = token;
  if (slot_) slot_->trust(identity_->role == Role::operator_ ? Trust::operator_ : Trust::viewer);
  auth_timer_.cancel();
  send(synbench::Json{{"type", "hello"}, {"role", role_name(identity_->role)}, {"id", identity_->id}, {"version", hub_->version()}, {"instance", instance_id()}});
}

void WsSession::handle_subscribe(const synbench::Json& doc, bool subscribe) {
  if (auto bad = unknown_field(doc, subscribe ? std::set<std::string>{"op", "channel", "rate_hz"} : std::set<std::string>{"op", "channel"}))
    return bad_message(*bad);
  if (!doc.contains("channel")) return bad_message("channel: required (telemetry, sweep or events)");
  if (!doc["channel"].is_string() || !kChannels.count(doc["channel"].get<std::string>()))
    return bad_message("channel: must be telemetry, sweep or events");
  const std::string channel = doc["channel"].get<std::string>();
  if (!subscribe) {
    (channel == "telemetry" ? telemetry_ : channel == "sweep" ? sweep_ : events_) = false;
    return send(synbench::Json{{"type", "unsubscribed"}, {"channel", channel}});
  }
  const WsLimits& lim = hub_->limits();
  synbench::Json rate = nullptr;
  if (channel == "telemetry") {
    double rate_hz = lim.default_rate_hz;
    if (doc.contains("rate_hz")) {
      if (!doc["rate_hz"].is_number()) return bad_message("rate_hz: must be a number");
      rate_hz = doc["rate_hz"].get<double>();
      if (!std::isfinite(rate_hz) || rate_hz <= 0 || rate_hz > lim.max_rate_hz)
        return bad_message("rate_hz: " + drivers::format_number(rate_hz) + " is outside (0, " + drivers::format_number(lim.max_rate_hz) + "]");
    }
    const double hub_rate_hz = 1000.0 / static_cast<double>(WsHub::kPeriod.count());
    period_ticks_ = hub_rate_hz / rate_hz;
    next_tick_.reset();
    telemetry_ = true;
    rate = rate_hz;
  } else if (doc.contains("rate_hz")) {
    return bad_message("rate_hz: only the telemetry channel has a rate");
  }
  send(synbench::Json{{"type", "subscribed"}, {"channel", channel}, {"rate_hz", rate}});
  if (channel == "sweep") {
    sweep_ = true;
    send(std::make_shared<const std::string>(hub_->sweep_message(hub_->bench().snapshot()->status)));
  } else if (channel == "events") {
    events_ = true;
    send(std::make_shared<const std::string>(state_message(hub_->bench().snapshot()->status)));
  }
}

void WsSession::handle_request(const synbench::Json& doc) {
  if (auto bad = unknown_field(doc, {"op", "id", "method", "path", "body"})) return bad_message(*bad);
  if (!doc.contains("method") || !doc["method"].is_string() || doc["method"].get<std::string>().empty())
    return bad_message("method: required, an HTTP method such as \"POST\"");
  if (!doc.contains("path") || !doc["path"].is_string() || doc["path"].get<std::string>().rfind('/', 0) != 0)
    return bad_message("path: required, starting with / (such as \"/api/bench/status\")");
  const synbench::Json id = doc.contains("id") ? doc["id"] : synbench::Json(nullptr);
  std::string body;
  if (doc.contains("body")) body = dump_json(doc["body"]);
  ++requests_in_flight_;
  // Through the REST router with this session's token: the same roles, lock and validation. A
  // bench command answers from the bench thread: the reply comes back to this session's strand.
  hub_->router().dispatch_async(doc["method"].get<std::string>(), doc["path"].get<std::string>(), "Bearer " + token_,
                                std::move(body), [self = shared_from_this(), id](Response r) {
                                  net::post(self->ws_.get_executor(), [self, id, r = std::move(r)] { self->reply(id, r); });
                                });
}

void WsSession::reply(const synbench::Json& id, const Response& r) {
  // A reply over the limit would overflow the send queue and drop the client: it is answered
  // with an error naming the way to get it in pieces instead.
  const std::size_t max = hub_->limits().max_reply_bytes;
  const auto too_large = [&](std::size_t bytes) {
    send(synbench::Json{{"type", "reply"}, {"id", id}, {"status", 413},
                        {"body", {{"error", {{"code", "reply_too_large"},
                                             {"message", "the reply is " + std::to_string(bytes) + " bytes, over the WebSocket's " +
                                                             std::to_string(max) + "-byte limit: ask for less (the points route "
                                                             "pages with ?offset=&limit=) or use REST"}}}}}},
         true);
  };
  if (r.body.size() > max) return too_large(r.body.size());
  try {
    synbench::Json reply_body = r.body;  // a text body (metrics, CSV) stays a string
    if (r.content_type.rfind("application/json", 0) == 0) {
      drivers::JsonParsed parsed = drivers::parse_json_text(r.body);
      if (parsed.ok()) reply_body = std::move(parsed.doc);
    }
    synbench::Json message{{"type", "reply"}, {"id", id}, {"status", r.status}, {"body", std::move(reply_body)}};
    if (!r.headers.empty()) {
      // Response headers a client may need (X-Total-Count of a page, Allow of a 405).
      synbench::Json headers = synbench::Json::object();
      for (const auto& [k, v] : r.headers) headers[k] = v;
      message["headers"] = std::move(headers);
    }
    auto text = std::make_shared<const std::string>(dump_json(message));
    if (text->size() > max) return too_large(text->size());
    send(std::move(text), true);
  } catch (const std::exception& e) {
    std::cerr << "synbench serve: websocket reply failed: " << drivers::escape_invalid_utf8(e.what()) << "\n";
    send(synbench::Json{{"type", "reply"}, {"id", id}, {"status", 500},
                        {"body", {{"error", {{"code", "internal"}, {"message", "the reply could not be built"}}}}}},
         true);
  }
}

void WsSession::bad_message(const std::string& message) {
  send(synbench::Json{{"type", "error"}, {"code", "bad_message"}, {"message", message}});
}

void WsSession::refuse(const std::string& message) {
  send(synbench::Json{{"type", "error"}, {"code", "unauthorized"}, {"message", message}});
  closing_ = true;
  auth_timer_.cancel();
  close_after_write_ = true;
  if (!writing_) close_if_due();
}

void WsSession::deliver(std::shared_ptr<const HubTick> tick) {
  net::post(ws_.get_executor(), [self = shared_from_this(), tick = std::move(tick)] { self->on_tick(*tick); });
}

void WsSession::on_tick(const HubTick& tick) {
  if (dropped_ || closing_) return;
  const WsLimits& lim = hub_->limits();
  // A token revoked (removed from tokens.json) ends its open sessions within a second, as it
  // ends its HTTP requests at once.
  if (identity_ && tick.index >= last_token_check_ + 50) {
    last_token_check_ = tick.index;
    if (!hub_->authenticate(token_)) return refuse("the token was revoked");
  }
  if (writing_ && std::chrono::steady_clock::now() - write_started_ > lim.write_stall)
    return drop("one write has been in flight for more than " + std::to_string(lim.write_stall.count()) + " ms");
  if (!identity_) return;
  if (telemetry_) {
    const double index = static_cast<double>(tick.index);
    // The first message after subscribing, or a gap longer than a period: restart the phase.
    if (!next_tick_ || *next_tick_ < index - period_ticks_) next_tick_ = index;
    if (index + 1e-9 >= *next_tick_) {
      *next_tick_ += period_ticks_;
      send(tick.telemetry);
    }
  }
  if (sweep_ && tick.sweep) send(tick.sweep);
  if (events_)
    for (const auto& e : tick.events) send(e);
}

void WsSession::send(const synbench::Json& message, bool reply) {
  send(std::make_shared<const std::string>(dump_json(message)), reply);
}

void WsSession::send(SharedText message, bool reply) {
  if (dropped_ || closing_) {
    if (reply) reply_done();
    return;
  }
  const WsLimits& lim = hub_->limits();
  if (queue_.size() + 1 > lim.max_queue_messages || queued_bytes_ + message->size() > lim.max_queue_bytes)
    return drop("its send queue is full (" + std::to_string(queue_.size()) + " messages, " + std::to_string(queued_bytes_) +
                " bytes): it does not read");
  queued_bytes_ += message->size();
  queue_.push_back({std::move(message), reply});
  if (!writing_) do_write();
}

void WsSession::do_write() {
  writing_ = true;
  write_started_ = std::chrono::steady_clock::now();
  ws_.async_write(net::buffer(*queue_.front().text), beast::bind_front_handler(&WsSession::on_write, shared_from_this()));
}

void WsSession::on_write(beast::error_code ec, std::size_t) {
  writing_ = false;
  if (dropped_) return;
  if (ec) return fail(ec, "write");
  queued_bytes_ -= queue_.front().text->size();
  const bool was_reply = queue_.front().reply;
  queue_.pop_front();
  if (was_reply) reply_done();
  if (dropped_) return;
  if (!queue_.empty()) {
    if (!writing_) do_write();
    return;
  }
  close_if_due();
}

void WsSession::close_if_due() {
  if (close_after_write_ && !dropped_) {
    close_after_write_ = false;
    ws_.async_close(websocket::close_reason(websocket::close_code::policy_error, "unauthorized"),
                    [self = shared_from_this()](beast::error_code e) {
                      if (e) fail(e, "close");
                    });
  }
}

void WsSession::evict() {
  if (dropped_) return;
  dropped_ = true;
  beast::error_code ec;
  auto& sock = beast::get_lowest_layer(ws_).socket();
  sock.shutdown(tcp::socket::shutdown_both, ec);
  sock.close(ec);
  auth_timer_.cancel();
  queue_.clear();
  queued_bytes_ = 0;
}

void WsSession::drop(const std::string& reason) {
  dropped_ = true;
  hub_->count_drop();
  std::cerr << "synbench serve: websocket client " << (identity_ ? identity_->id : std::string("(unauthenticated)"))
            << " dropped: " << reason << "\n";
  beast::error_code ec;
  auto& sock = beast::get_lowest_layer(ws_).socket();
  sock.shutdown(tcp::socket::shutdown_both, ec);
  sock.close(ec);  // the write in flight and the read complete with operation_aborted
  auth_timer_.cancel();
  queue_.clear();
  queued_bytes_ = 0;
}

}  // namespace synbench::http
