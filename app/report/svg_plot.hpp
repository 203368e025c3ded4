// Our small SVG writer for the report (issue 25): line plots, bar charts and heat maps with
// iso-lines as self-contained inline SVG (no script, no external resource), each titled.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bench/efficiency_contours.hpp"

namespace synbench::report {

struct XYSeries {
  std::string name;
  std::vector<std::array<double, 2>> points;  // {x, y}, drawn in order; gaps where y is NaN
  bool dashed = false;
  // Parallel to points (or empty): the standard uncertainty u (k = 1) of y, drawn as an error bar
  // of +/- 2u (about 95 %); NaN: none. hollow: the point's difference is not significant at 95 %.
  std::vector<double> u = {};
  std::vector<bool> hollow = {};
};
struct XYPlot {
  std::string title, x_label, y_label;
  std::vector<XYSeries> series;
  std::string note = {};  // under the legend, e.g. "bars: ±2u, 95 %"
};
// A line plot with markers, axes with "nice" ticks and a legend; colours from one palette.
// Error bars are <line class="eb" data-u="u"> (the report test reads them back).
std::string svg_xy(const XYPlot& p);

struct Bar {
  double from = 0, to = 0, value = 0;
};
// Bars over [from, to) on a numeric axis.
std::string svg_bars(const std::string& title, const std::string& x_label, const std::string& y_label,
                     const std::vector<Bar>& bars);

struct HeatPlot {
  std::string title, x_label, y_label;
  std::vector<double> xs, ys;                          // column and row positions, ascending
  std::vector<std::vector<std::optional<double>>> z;   // z[row][column]; empty: a hole (not drawn)
  bool categorical = false;  // true: equal-width cells labelled with their value in % (the measured map)
  std::vector<bench::ContourLine> lines;  // iso-lines over the field, labelled with their level in %
};
std::string svg_heat(const HeatPlot& p);

// Text with <, >, & and quotes escaped, for HTML and SVG alike.
std::string escape_xml(const std::string& text);

}  // namespace synbench::report
