// The one-click report of a sweep (issue 25, docs/report.md): one self-contained HTML file with
// the sweep, its plan, the bench and software metadata, the uncertainty summary (issue 26), every
// result figure as inline SVG (with +/- 2u error bars where the points carry u), the numeric tables
// (with +/- u and significance) and the exclusions; the points CSV goes beside it. Pure rendering: the caller
// reads the store (make_sweep_report does it for the CLI and the daemon alike).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bench/analysis.hpp"
#include "db/store.hpp"
#include "db/types.hpp"

namespace synbench::report {

// Where and when the report is made (outside the pure rendering: the clock and the host).
struct ReportContext {
  std::string generated_at;  // UTC, ISO 8601
  std::string host;          // where the report was made
};

struct ReportInput {
  db::Sweep sweep;
  std::vector<db::PointRow> rows;
  bench::Analysis analysis;
  ReportContext context;
};

// The HTML page.
std::string render_report(const ReportInput& in);

// "synbench-report-<id>-<name-slug>-<YYYY-MM-DD>" (no extension), the date from generated_at.
std::string report_base_name(const db::Sweep& sweep, const std::string& generated_at);

struct SweepReport {
  std::string base_name;  // add .html / .csv
  std::string html;
  std::string csv;        // db::points_to_csv of every stored point
};

// Reads the sweep and its points from `store`, analyses them (default options) and renders.
db::Result<SweepReport> make_sweep_report(db::Store& store, std::int64_t sweep_id, const ReportContext& context);

// The context of now on this host.
ReportContext current_context();

}  // namespace synbench::report
