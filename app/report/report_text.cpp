// The report's number and table-cell text; see report_text.hpp.
#include "app/report/report_text.hpp"

#include <cmath>
#include <cstdio>

#include "app/report/svg_plot.hpp"

namespace synbench::report {

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string shortest(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string td(const std::string& text) { return "<td>" + escape_xml(text) + "</td>"; }

}  // namespace synbench::report
