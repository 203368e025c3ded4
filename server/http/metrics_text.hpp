// The daemon's Prometheus metrics (GET /metrics, text format 0.0.4): one table of every metric,
// its type and help, from which both the exposition and docs/api.md's metrics table are made.
// Names follow Prometheus's naming guide: units spelled out as the suffix (`_amperes`, `_volts`,
// `_watts`, `_celsius`, `_seconds`; rpm as `_revolutions_per_minute`), counters end in `_total`.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/bench_status.hpp"

namespace synbench::http {

struct WsCounts;
struct ConnectionCounts;

struct MetricSpec {
  const char* name;
  const char* type;    // "gauge" or "counter"
  const char* help;
  const char* labels;  // "" or the label names, e.g. "status"
  const char* when;    // when the metric is present: "always" or its condition
};

// Every metric /metrics may show, in the order it shows them.
const std::vector<MetricSpec>& metric_specs();

// The exposition of one status snapshot and the daemon's counters.
std::string prometheus_text(const app::BenchStatus& s, const std::map<int, std::uint64_t>& http_by_status,
                            const std::optional<WsCounts>& ws, const std::optional<ConnectionCounts>& connections);

// docs/api.md's table of the metrics (a test keeps the two equal).
std::string metrics_table_markdown();

}  // namespace synbench::http
