// The uncertainty parts of the sweep report (issue 26, docs/report.md, docs/uncertainty.md): read
// from the analysis JSON (bench::to_json, docs/analysis.md: the keys are the contract the dashboard
// draws too), so the report and the dashboard show the same numbers. A summary section with the
// counts of significant differences, the deltas table and the efficiency map's u per cell, each
// with +/- u (k = 1) and significance at 95 %; "no uncertainty stored" where the points carry none.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "db/types.hpp"
#include "drivers/json_fwd.hpp"

namespace synbench::report {

// A number of the JSON object j at key, or NaN when missing or null.
double json_number(const synbench::Json& j, const char* key);
// A boolean at key, or nullopt when missing or null (unknown: never "significant").
std::optional<bool> json_bool(const synbench::Json& j, const char* key);

// u with two significant digits ("0.013"), "–" when unknown.
std::string u_text(double u);
// "yes", "no" or "–".
std::string significance_text(std::optional<bool> s);

// How many stored points carry a standard uncertainty of pdcm_W.
std::size_t points_with_u(const std::vector<db::PointRow>& rows);

// <h2 id="uncertainty"> with what the bars and the +/- columns are, the counts of significant
// ME - MTPA differences and deltas, and the line naming docs/uncertainty.md.
std::string uncertainty_section(const synbench::Json& analysis, const std::vector<db::PointRow>& rows);

// <table id="deltas">: every delta against the reference with its u and significance.
std::string deltas_table(const synbench::Json& analysis);

// <table class="eta-u-grid"> per configuration: the efficiency map's u, speed x load.
std::string efficiency_u_grids(const synbench::Json& analysis);

}  // namespace synbench::report
