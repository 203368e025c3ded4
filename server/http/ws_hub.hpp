// The WebSocket hub: the state every /ws session shares (after the shared_state of Beast's
// chat-multi example). A 50 Hz timer on the io_context samples BenchRuntime::status() (a copy
// under the bench's mutex, microseconds), builds each push message once (telemetry, sweep
// progress on change, new events by sequence number, the state on change) and hands the same
// immutable tick to every session, which decides on its own strand what its subscriptions and
// telemetry rate take from it. The bench thread never waits on a client.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include "drivers/json.hpp"

#include "server/http/api_routes.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

struct WsLimits {
  std::size_t max_message_bytes = 64 * 1024;       // a bigger client message closes with 1009
  std::size_t max_queue_messages = 256;            // per session; beyond, the client is dropped
  std::size_t max_queue_bytes = 1 << 20;           // likewise
  // A request's reply bigger than this is answered 413 `reply_too_large` instead: one message
  // near max_queue_bytes would drop the client that asked for it.
  std::size_t max_reply_bytes = 512 * 1024;
  std::chrono::milliseconds write_stall{5000};     // one write in flight longer: dropped
  // Requests of one session whose reply is not yet written: at this many the session reads no
  // further message until one is, so a burst costs the io thread this many replies, not one per
  // message sent (a client that never reads is then dropped by write_stall).
  std::size_t max_requests_in_flight = 8;
  std::chrono::milliseconds auth_timeout{5000};    // for the first message, {"op":"auth"}
  // The kernel's send buffer of a session's socket. Bounded so a reader that stalls fills it in
  // seconds and the stall is seen; autotuned it could absorb minutes of telemetry.
  int socket_send_buffer_bytes = 64 * 1024;
  double max_rate_hz = 50, default_rate_hz = 10;
};

using SharedText = std::shared_ptr<const std::string>;

// One sample of the hub, shared read-only by every session.
struct HubTick {
  std::uint64_t index = 0;  // 20 ms periods since the hub started (skipped periods count)
  SharedText telemetry;     // always
  SharedText sweep;         // when the sweep's id, state, done or total changed
  std::vector<SharedText> events;  // new events and state changes, in order
};

class WsSession;

class WsHub : public std::enable_shared_from_this<WsHub> {
 public:
  static constexpr std::chrono::milliseconds kPeriod{20};  // 50 Hz, the highest client rate

  WsHub(boost::asio::io_context& io, BenchRuntime& bench, const Router& router, Authenticator auth, std::string version,
        WsLimits limits = {});
  // Starts the sampling timer; stop() ends it (idempotent), leaving sessions to their sockets.
  void start();
  void stop();

  void join(const std::shared_ptr<WsSession>& session);
  void leave(const WsSession* session);
  std::size_t session_count() const;
  void count_drop() { ++dropped_; }
  std::uint64_t dropped() const { return dropped_; }

  BenchRuntime& bench() const { return bench_; }
  const Router& router() const { return router_; }
  std::optional<Identity> authenticate(std::string_view token) const { return auth_ ? auth_(token) : std::nullopt; }
  const std::string& version() const { return version_; }
  const WsLimits& limits() const { return limits_; }

  // The sweep message of `s` now (for a fresh subscription; ETA from the hub's tracking).
  std::string sweep_message(const BenchStatus& s) const;

 private:
  void schedule();
  void on_tick();

  boost::asio::io_context& io_;
  BenchRuntime& bench_;
  const Router& router_;
  Authenticator auth_;
  std::string version_;
  WsLimits limits_;
  std::unique_ptr<boost::asio::steady_timer> timer_;  // destroyed by stop(), inside the io thread
  std::chrono::steady_clock::time_point start_{};
  std::uint64_t index_ = 0;
  std::atomic<std::uint64_t> dropped_{0};

  mutable std::mutex mutex_;  // guards sessions_ and the sweep tracking read by sweep_message
  std::map<const WsSession*, std::weak_ptr<WsSession>> sessions_;
  // Change tracking, on the hub's timer only (sweep fields also read under mutex_).
  bool primed_ = false;
  std::uint64_t last_event_seq_ = 0;
  std::string last_state_key_, last_sweep_key_;
  std::int64_t eta_sweep_id_ = 0;
  std::size_t eta_done0_ = 0;
  std::chrono::steady_clock::time_point eta_t0_{};
  std::optional<double> eta_s_;
};

// Push messages, exposed for tests. `sent_unix_ms` is the wall clock (ms since the epoch, with a
// fraction) when the hub built the message: clients measure delivery latency against it.
std::string telemetry_message(const BenchStatus& s, double sent_unix_ms);
synbench::Json sweep_json(const BenchStatus& s, std::optional<double> eta_s);
std::string state_message(const BenchStatus& s);
std::string event_message(const BenchEvent& e);
double unix_ms_now();

}  // namespace synbench::http
