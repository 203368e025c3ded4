// A thread of its own for the CPU-heavy routes (plan estimates, analyses, exports of a sweep's
// points), so that the io thread, and with it an operator's E-stop, never waits behind them.
// One thread, and at most `max_queued` requests waiting for it: more are refused at once with
// 503 `busy` (Retry-After: 1) instead of piling up.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>

#include <boost/asio/thread_pool.hpp>

#include "server/http/router.hpp"

namespace synbench::http {

class Worker {
 public:
  explicit Worker(std::size_t max_queued = 8) : max_queued_(max_queued) {}
  ~Worker() { pool_.join(); }
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // `handler` as a route handler that runs on the worker thread.
  AsyncHandler offload(Handler handler);
  // `route` (with a synchronous handler) run on the worker thread, its body check
  // (check_body against its request_schema) included: a heavy route's body is never parsed on
  // the io thread, nor at all when the queue is full.
  Route offloaded(Route route);
  // Runs `job` on the worker thread (its set-up, e.g. the thread's own store connection).
  void post(std::function<void()> job);
  // Stops taking work and waits for what runs.
  void stop() { pool_.join(); }

 private:
  boost::asio::thread_pool pool_{1};
  std::atomic<std::size_t> queued_{0};
  std::size_t max_queued_;
};

}  // namespace synbench::http
