// The report's number and table-cell text, shared by its HTML parts (sweep_report.cpp,
// report_uncertainty.cpp) so a figure reads the same wherever it is printed.
#pragma once

#include <string>

namespace synbench::report {

// v with `decimals` decimals; "–" when v is not finite (a figure that could not be computed).
std::string fixed(double v, int decimals);
// v in the shortest of %g's forms: a plan's own values, printed as given.
std::string shortest(double v);
// One table cell holding the text, escaped.
std::string td(const std::string& text);

}  // namespace synbench::report
