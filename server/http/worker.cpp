// The worker thread's queue; see worker.hpp.
#include "server/http/worker.hpp"

#include <exception>
#include <stdexcept>

#include <boost/asio/post.hpp>

namespace synbench::http {

AsyncHandler Worker::offload(Handler handler) {
  return [this, handler = std::move(handler)](const Request& req, Reply reply) {
    if (queued_.fetch_add(1) >= max_queued_) {
      --queued_;
      Response r = error_response(503, "busy", "the daemon's worker has " + std::to_string(max_queued_) +
                                                   " requests waiting; try again shortly");
      r.headers.emplace_back("Retry-After", "1");
      return reply(std::move(r));
    }
    boost::asio::post(pool_, [this, handler, req, reply = std::move(reply)] {
      Response r;
      try {
        r = handler(req);
      } catch (const std::exception& e) {
        r = error_response(500, "internal", e.what());
      }
      --queued_;
      reply(std::move(r));
    });
  };
}

Route Worker::offloaded(Route route) {
  if (!route.handler) throw std::invalid_argument(route.method + " " + route.pattern + ": Worker::offloaded needs a synchronous handler");
  route.async_handler = offload([handler = std::move(route.handler), schema = route.request_schema,
                                 code = route.body_error_code](const Request& req) {
    if (!schema) return handler(req);
    Request checked = req;
    if (auto bad = check_body(*schema, code, checked)) return std::move(*bad);
    return handler(checked);
  });
  route.handler = nullptr;
  route.body_checked_by_handler = true;
  return route;
}

void Worker::post(std::function<void()> job) { boost::asio::post(pool_, std::move(job)); }

}  // namespace synbench::http
