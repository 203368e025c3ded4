// The daemon's REST routes: the table that Router dispatches and the OpenAPI document lists.
// The router checks each body against its route's published schema (400 naming the JSON
// pointer); a handler calls the bench runtime and shapes the JSON answer, whose schema the
// OpenAPI document publishes too (response_schemas.hpp). docs/api.md describes every route.
#pragma once

#include "drivers/json.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <mutex>
#include <string>

#include "app/bench_runtime.hpp"
#include "emulator/twin_config.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

using app::BenchRuntime;
using app::BenchEvent;
using app::BenchStatus;

// Request counts by status, for /metrics.
// WebSocket clients connected now and dropped so far (slow readers), for /metrics.
struct WsCounts {
  std::size_t clients = 0;
  std::uint64_t dropped = 0;
};

// Open HTTP and WebSocket connections, and those closed to make room for others.
struct ConnectionCounts {
  std::size_t open = 0;
  std::uint64_t evicted = 0;
};

class HttpMetrics {
 public:
  void count(int status);
  std::map<int, std::uint64_t> by_status() const;
  // The WebSocket hub's counts, once it exists (it is built after the routes).
  void set_ws_source(std::function<WsCounts()> source) {
    std::lock_guard lock(mutex_);
    ws_source_ = std::move(source);
  }
  std::optional<WsCounts> ws() const {
    std::lock_guard lock(mutex_);
    if (!ws_source_) return std::nullopt;
    return ws_source_();
  }
  // The server's connection counts, once it exists.
  void set_connection_source(std::function<ConnectionCounts()> source) {
    std::lock_guard lock(mutex_);
    connection_source_ = std::move(source);
  }
  std::optional<ConnectionCounts> connections() const {
    std::lock_guard lock(mutex_);
    if (!connection_source_) return std::nullopt;
    return connection_source_();
  }

 private:
  mutable std::mutex mutex_;
  std::map<int, std::uint64_t> by_status_;
  std::function<WsCounts()> ws_source_;
  std::function<ConnectionCounts()> connection_source_;
};

// One operator commands the bench at a time. The first operator command claims the lock; another
// operator's commands are refused (409) until the holder releases it or has been idle for
// kIdle, so a vanished client cannot lock the bench out for good. E-stop never needs it.
class ControlLock {
 public:
  static constexpr std::chrono::seconds kIdle{600};
  using Clock = std::chrono::steady_clock;

  // True when `id` holds the lock now (claimed or renewed).
  bool claim(const std::string& id) {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    if (holder_.empty() || holder_ == id || now - last_ > kIdle) holder_ = id;
    if (holder_ != id) return false;
    last_ = now;
    return true;
  }
  // False when another operator holds it.
  bool release(const std::string& id) {
    std::lock_guard lock(mutex_);
    if (holder_.empty() || holder_ == id || Clock::now() - last_ > kIdle) {
      holder_.clear();
      return true;
    }
    return false;
  }
  synbench::Json describe() const {
    std::lock_guard lock(mutex_);
    const auto idle_s = std::chrono::duration<double>(Clock::now() - last_).count();
    if (holder_.empty() || idle_s > static_cast<double>(kIdle.count())) return {{"holder", nullptr}};
    return {{"holder", holder_}, {"idle_s", idle_s}, {"expires_in_s", static_cast<double>(kIdle.count()) - idle_s}};
  }

 private:
  mutable std::mutex mutex_;
  std::string holder_;
  Clock::time_point last_{};
};

// 409 `locked`, naming the holder.
Response locked(const ControlLock& lock);

struct ApiContext {
  BenchRuntime& bench;
  const emulator::TwinConfig& twin;  // the firmware's estimator settings (GET /api/estimators)
  ControlLock& control;
  HttpMetrics& metrics;
  std::string version;
};

// Adds every route to `router`; the OpenAPI route reads `router` itself when called.
void add_api_routes(Router& router, ApiContext ctx);

synbench::Json status_json(const BenchStatus& s);
// The bench's refusal as an HTTP status: 409 for the bench's state, 502 for a device, 503 while
// the daemon stops or its queue is full, 500 for the store.
int http_status(app::Refused r);
// A command's outcome: its refusal as an error, else `ok_status` with the status after it.
Response outcome_response(const app::Outcome& o, int ok_status = 200);
// The bench thread's callback for a command: hands outcome_response to `reply`, an exception
// on the way being a 500 rather than the end of the bench thread.
BenchRuntime::Done answer(Reply reply, int ok_status = 200);
// The snapshot's status text as a 200.
Response status_response(const app::StatusSnapshot& s);
// The supervisor's phase as the API names it: "normal", "stopping_load", ... "estopped".
const char* phase_name(bench::SafetyPhase p);

}  // namespace synbench::http
