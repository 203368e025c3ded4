// One /ws connection after the HTTP upgrade (the HTTP session has already checked Host and
// Origin). Protocol (docs/api.md): the first message must be {"op":"auth","token":...} within
// 5 s, else an `unauthorized` error and close 1008; then subscribe/unsubscribe to telemetry
// (at the client's rate), sweep and events, and `request`s dispatched through the REST Router
// with the session's token, so roles, the control lock and validation are REST's own.
// Requests: at most WsLimits::max_requests_in_flight unanswered before the session reads on.
// Writes: one in flight, behind a bounded queue; a client whose queue overflows or whose write
// stalls is dropped (its socket closed) so it costs the daemon neither memory nor other
// clients' rate.
#pragma once

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include "drivers/json.hpp"

#include "server/http/connection_registry.hpp"
#include "server/http/ws_hub.hpp"

namespace synbench::http {

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  // `slot` is the connection's registration, held for the session's life: the session raises its
  // trust once authenticated and closes itself when the server needs the room.
  WsSession(boost::asio::ip::tcp::socket&& socket, std::shared_ptr<WsHub> hub, std::shared_ptr<ConnectionSlot> slot);
  ~WsSession();
  // Answers the upgrade request with 101 and starts the session.
  void run(boost::beast::http::request<boost::beast::http::string_body> req);
  // From the hub, on any thread: the session takes what its subscriptions want on its strand.
  void deliver(std::shared_ptr<const HubTick> tick);

 private:
  void on_accept(boost::beast::error_code ec);
  void do_read();
  void on_read(boost::beast::error_code ec, std::size_t bytes);
  void on_auth_timeout(boost::beast::error_code ec);
  void on_tick(const HubTick& tick);
  void handle(const std::string& text);
  void handle_auth(const synbench::Json& doc);
  void handle_subscribe(const synbench::Json& doc, bool subscribe);
  void handle_request(const synbench::Json& doc);
  // Sends the router's answer to request `id`, on this session's strand.
  void reply(const synbench::Json& id, const Response& r);
  void bad_message(const std::string& message);
  // An `unauthorized` error, then close 1008 once it is written.
  void refuse(const std::string& message);
  // `reply`: the message answers a request (it counts in requests_in_flight_ until written).
  void send(SharedText message, bool reply = false);
  void send(const synbench::Json& message, bool reply = false);
  // A request's reply was written (or will never be): reading resumes if it waited for this.
  void reply_done();
  void do_write();
  void on_write(boost::beast::error_code ec, std::size_t bytes);
  // The planned close (after refuse()) once the queue is written.
  void close_if_due();
  // Closes the socket at once: for a client that does not read.
  void drop(const std::string& reason);
  // Closes the socket at once without counting a slow client: the server needed the room.
  void evict();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  std::shared_ptr<WsHub> hub_;
  std::shared_ptr<ConnectionSlot> slot_;
  std::uint64_t last_token_check_ = 0;  // the hub tick the token was last found valid at
  boost::beast::flat_buffer buffer_;
  boost::asio::steady_timer auth_timer_;
  bool joined_ = false;

  // Authentication: the token is kept to authorise each request as REST does (so a revoked
  // token stops working) and never logged.
  std::optional<Identity> identity_;
  std::string token_;

  // Subscriptions.
  bool telemetry_ = false, sweep_ = false, events_ = false;
  double period_ticks_ = 5;           // hub ticks per telemetry message (50 Hz / rate)
  std::optional<double> next_tick_;   // hub tick index of the next telemetry message

  // The write queue: at most one async_write in flight.
  struct Queued {
    SharedText text;
    bool reply;
  };
  std::deque<Queued> queue_;
  std::size_t requests_in_flight_ = 0;  // dispatched requests whose reply is not yet written
  bool read_paused_ = false;            // no read pending: waiting for requests_in_flight_ to fall
  std::size_t queued_bytes_ = 0;
  bool writing_ = false;
  std::chrono::steady_clock::time_point write_started_{};
  bool closing_ = false;  // a close is planned or under way: nothing more is queued
  bool close_after_write_ = false;
  bool dropped_ = false;
};

}  // namespace synbench::http
