// GET /api/telemetry/history: the daemon's telemetry ring (app/telemetry_history.hpp) as columns,
// so a page fills its charts at once on load or reconnect, and after a daemon restart. Built on
// the worker thread: 15 min of samples are a few MB of JSON.
#pragma once

#include "app/telemetry_history.hpp"
#include "server/http/router.hpp"
#include "server/http/worker.hpp"

namespace synbench::http {

// The ring's samples as {"period_s", "capacity", "t_s": [...], "channels": {name: [...]}}.
synbench::Json history_json(const app::TelemetryHistory& history, double span_s, std::size_t max_points);

void add_telemetry_routes(Router& router, const app::TelemetryHistory& history, Worker& worker);

}  // namespace synbench::http
