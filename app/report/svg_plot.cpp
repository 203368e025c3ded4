// Inline SVG plots for the report; see svg_plot.hpp. Fixed 640 x 360 canvas, scaled by the page.
#include "app/report/svg_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace synbench::report {
namespace {

constexpr double kW = 640, kH = 380, kLeft = 70, kRight = 150, kTop = 52, kBottom = 50;
constexpr double kPlotW = kW - kLeft - kRight, kPlotH = kH - kTop - kBottom;
constexpr double kCoverage = 2;  // error bars: +/- 2u (about 95 %)
constexpr std::array<const char*, 8> kPalette = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                                 "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

std::string num(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
std::string px(double v) { return num(v, 1); }

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void settle() {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12) lo -= 0.5, hi += 0.5;
  }
};

// "Nice" ticks (1, 2 or 5 x 10^k apart) covering [lo, hi]; widens the range to them.
std::vector<double> ticks(Range& r) {
  const double raw = (r.hi - r.lo) / 5;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double n = raw / mag;
  const double step = (n < 1.5 ? 1 : n < 3.5 ? 2 : n < 7.5 ? 5 : 10) * mag;
  r.lo = std::floor(r.lo / step) * step;
  r.hi = std::ceil(r.hi / step) * step;
  std::vector<double> out;
  for (double t = r.lo; t <= r.hi + step * 1e-6; t += step) out.push_back(std::fabs(t) < step * 1e-9 ? 0.0 : t);
  return out;
}
int decimals_of(const std::vector<double>& t) {
  if (t.size() < 2) return 0;
  const double step = t[1] - t[0];
  return step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
}

std::string open_svg(const std::string& title) {
  // Two lines: what it is, then " — sweep ..., configuration" (too long for one line at this width).
  const auto dash = title.find(" — ");
  const std::string what = title.substr(0, dash), which = dash == std::string::npos ? "" : title.substr(dash + 5);
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " + px(kW) + " " + px(kH) +
         "\" role=\"img\" class=\"plot\"><title>" + escape_xml(title) + "</title>" +
         "<text x=\"" + px(kW / 2) + "\" y=\"16\" class=\"t\" text-anchor=\"middle\">" + escape_xml(what) + "</text>" +
         "<text x=\"" + px(kW / 2) + "\" y=\"32\" text-anchor=\"middle\">" + escape_xml(which) + "</text>";
}

// Axes, grid, ticks and labels of a numeric plot area.
std::string axes(Range& x, Range& y, const std::string& x_label, const std::string& y_label,
                 const std::vector<double>& xt, const std::vector<double>& yt) {
  std::string s = "<g class=\"ax\">";
  const int xd = decimals_of(xt), yd = decimals_of(yt);
  for (double t : xt) {
    const double X = kLeft + (t - x.lo) / (x.hi - x.lo) * kPlotW;
    s += "<line x1=\"" + px(X) + "\" y1=\"" + px(kTop) + "\" x2=\"" + px(X) + "\" y2=\"" + px(kTop + kPlotH) +
         "\" class=\"g\"/><text x=\"" + px(X) + "\" y=\"" + px(kTop + kPlotH + 16) + "\" text-anchor=\"middle\">" +
         num(t, xd) + "</text>";
  }
  for (double t : yt) {
    const double Y = kTop + kPlotH - (t - y.lo) / (y.hi - y.lo) * kPlotH;
    s += "<line x1=\"" + px(kLeft) + "\" y1=\"" + px(Y) + "\" x2=\"" + px(kLeft + kPlotW) + "\" y2=\"" + px(Y) +
         "\" class=\"g\"/><text x=\"" + px(kLeft - 6) + "\" y=\"" + px(Y + 4) + "\" text-anchor=\"end\">" +
         num(t, yd) + "</text>";
  }
  s += "<rect x=\"" + px(kLeft) + "\" y=\"" + px(kTop) + "\" width=\"" + px(kPlotW) + "\" height=\"" + px(kPlotH) +
       "\" class=\"f\"/>";
  s += "<text x=\"" + px(kLeft + kPlotW / 2) + "\" y=\"" + px(kH - 12) + "\" text-anchor=\"middle\" class=\"l\">" +
       escape_xml(x_label) + "</text>";
  s += "<text transform=\"translate(16 " + px(kTop + kPlotH / 2) + ") rotate(-90)\" text-anchor=\"middle\" class=\"l\">" +
       escape_xml(y_label) + "</text></g>";
  return s;
}

std::string legend_entry(std::size_t k, const std::string& name, const char* colour, bool dashed) {
  const double y = kTop + 8 + 16 * static_cast<double>(k);
  return "<line x1=\"" + px(kW - kRight + 10) + "\" y1=\"" + px(y) + "\" x2=\"" + px(kW - kRight + 30) + "\" y2=\"" +
         px(y) + "\" stroke=\"" + colour + "\" stroke-width=\"2\"" + (dashed ? " stroke-dasharray=\"5 3\"" : "") +
         "/><text x=\"" + px(kW - kRight + 34) + "\" y=\"" + px(y + 4) + "\">" + escape_xml(name) + "</text>";
}

// Viridis-like colour of t in [0, 1].
std::string colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> stops = {
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4;
  const auto i = std::min<std::size_t>(3, static_cast<std::size_t>(t));
  const double f = t - static_cast<double>(i);
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(stops[i][0] + f * (stops[i + 1][0] - stops[i][0])),
                static_cast<int>(stops[i][1] + f * (stops[i + 1][1] - stops[i][1])),
                static_cast<int>(stops[i][2] + f * (stops[i + 1][2] - stops[i][2])));
  return buf;
}

std::string percent(double v) {
  const double p = v * 100;
  return num(p, std::fabs(p - std::round(p)) < 1e-6 ? 0 : 1) + " %";
}

}  // namespace

std::string escape_xml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  return out;
}

std::string svg_xy(const XYPlot& p) {
  const auto u_of = [](const XYSeries& s, std::size_t i) { return i < s.u.size() && std::isfinite(s.u[i]) ? s.u[i] : std::nan(""); };
  Range x, y;
  for (const auto& s : p.series)
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const auto& pt = s.points[i];
      if (!std::isfinite(pt[1])) continue;
      x.add(pt[0]), y.add(pt[1]);
      if (const double u = u_of(s, i); std::isfinite(u)) y.add(pt[1] - kCoverage * u), y.add(pt[1] + kCoverage * u);
    }
  x.settle();
  y.settle();
  const auto xt = ticks(x), yt = ticks(y);
  std::string out = open_svg(p.title) + axes(x, y, p.x_label, p.y_label, xt, yt);
  const auto Yof = [&](double v) { return kTop + kPlotH - (v - y.lo) / (y.hi - y.lo) * kPlotH; };
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const auto& s = p.series[k];
    const char* c = kPalette[k % kPalette.size()];
    std::string path, marks;
    bool pen = false;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const auto& pt = s.points[i];
      if (!std::isfinite(pt[0]) || !std::isfinite(pt[1])) {
        pen = false;
        continue;
      }
      const double X = kLeft + (pt[0] - x.lo) / (x.hi - x.lo) * kPlotW;
      const double Y = Yof(pt[1]);
      path += (pen ? "L" : "M") + px(X) + " " + px(Y);
      pen = true;
      const bool hollow = i < s.hollow.size() && s.hollow[i];
      marks += "<circle cx=\"" + px(X) + "\" cy=\"" + px(Y) + (hollow ? "\" r=\"3.5\" fill=\"#fff\" class=\"insignificant\"/>" : "\" r=\"2.5\"/>");
      if (const double u = u_of(s, i); std::isfinite(u)) {
        const double lo = Yof(pt[1] - kCoverage * u), hi = Yof(pt[1] + kCoverage * u);
        marks += "<line class=\"eb\" data-u=\"" + num(u, 9) + "\" x1=\"" + px(X) + "\" y1=\"" + px(lo) + "\" x2=\"" + px(X) + "\" y2=\"" + px(hi) +
                 "\"/><line x1=\"" + px(X - 3) + "\" y1=\"" + px(lo) + "\" x2=\"" + px(X + 3) + "\" y2=\"" + px(lo) + "\"/><line x1=\"" + px(X - 3) +
                 "\" y1=\"" + px(hi) + "\" x2=\"" + px(X + 3) + "\" y2=\"" + px(hi) + "\"/>";
      }
    }
    out += "<g stroke=\"" + std::string(c) + "\" fill=\"" + c + "\"><path d=\"" + path + "\" fill=\"none\" stroke-width=\"1.6\"" +
           (s.dashed ? " stroke-dasharray=\"5 3\"" : "") + "/>" + marks + "</g>";
    if (k < 18) out += legend_entry(k, s.name, c, s.dashed);
  }
  // the note's lines ('\n') in the legend's column, above the plot's bottom
  std::vector<std::string> lines;
  for (std::size_t from = 0; !p.note.empty() && from <= p.note.size();) {
    const auto to = std::min(p.note.find('\n', from), p.note.size());
    lines.push_back(p.note.substr(from, to - from));
    from = to + 1;
  }
  for (std::size_t i = 0; i < lines.size(); ++i)
    out += "<text x=\"" + px(kW - kRight + 10) + "\" y=\"" + px(kTop + kPlotH - 14 * static_cast<double>(lines.size() - 1 - i)) +
           "\" class=\"note\">" + escape_xml(lines[i]) + "</text>";
  return out + "</svg>";
}

std::string svg_bars(const std::string& title, const std::string& x_label, const std::string& y_label,
                     const std::vector<Bar>& bars) {
  Range x, y;
  y.add(0);
  for (const auto& b : bars) x.add(b.from), x.add(b.to), y.add(b.value);
  x.settle();
  y.settle();
  const auto xt = ticks(x), yt = ticks(y);
  std::string out = open_svg(title) + axes(x, y, x_label, y_label, xt, yt) + "<g fill=\"#1f77b4\" stroke=\"#fff\">";
  for (const auto& b : bars) {
    const double X0 = kLeft + (b.from - x.lo) / (x.hi - x.lo) * kPlotW;
    const double X1 = kLeft + (b.to - x.lo) / (x.hi - x.lo) * kPlotW;
    const double Y = kTop + kPlotH - (b.value - y.lo) / (y.hi - y.lo) * kPlotH;
    out += "<rect x=\"" + px(X0) + "\" y=\"" + px(Y) + "\" width=\"" + px(X1 - X0) + "\" height=\"" +
           px(kTop + kPlotH - Y) + "\"/>";
  }
  return out + "</g></svg>";
}

std::string svg_heat(const HeatPlot& p) {
  Range z;
  for (const auto& row : p.z)
    for (const auto& v : row)
      if (v) z.add(*v);
  z.settle();
  std::string out = open_svg(p.title);
  const std::size_t nx = p.xs.size(), ny = p.ys.size();
  // Cell edges: equal widths for categories, else halfway between neighbouring positions.
  const auto edges = [](const std::vector<double>& v, bool categorical) {
    std::vector<double> e;
    for (std::size_t i = 0; i <= v.size(); ++i) {
      if (categorical) e.push_back(static_cast<double>(i));
      else if (i == 0) e.push_back(v.front());
      else if (i == v.size()) e.push_back(v.back());
      else e.push_back((v[i - 1] + v[i]) / 2);
    }
    return e;
  };
  const auto ex = edges(p.xs, p.categorical), ey = edges(p.ys, p.categorical);
  if (nx == 0 || ny == 0) return out + "</svg>";
  Range xr{ex.front(), ex.back()}, yr{ey.front(), ey.back()};
  xr.settle();
  yr.settle();
  const auto X = [&](double v) { return kLeft + (v - xr.lo) / (xr.hi - xr.lo) * kPlotW; };
  const auto Y = [&](double v) { return kTop + kPlotH - (v - yr.lo) / (yr.hi - yr.lo) * kPlotH; };
  std::string cells = "<g class=\"cells\">";
  for (std::size_t r = 0; r < ny; ++r)
    for (std::size_t c = 0; c < nx; ++c) {
      if (r >= p.z.size() || c >= p.z[r].size() || !p.z[r][c]) continue;
      const double v = *p.z[r][c];
      cells += "<rect x=\"" + px(X(ex[c])) + "\" y=\"" + px(Y(ey[r + 1])) + "\" width=\"" + px(X(ex[c + 1]) - X(ex[c]) + 0.3) +
               "\" height=\"" + px(Y(ey[r]) - Y(ey[r + 1]) + 0.3) + "\" fill=\"" + colour((v - z.lo) / (z.hi - z.lo)) + "\"/>";
      if (p.categorical)
        cells += "<text x=\"" + px(X(ex[c] + 0.5)) + "\" y=\"" + px(Y(ey[r] + 0.5) + 4) + "\" text-anchor=\"middle\" class=\"v\">" +
                 num(v * 100, 1) + "</text>";
    }
  out += cells + "</g>";
  // Axes: category labels, or numeric ticks.
  std::string ax = "<g class=\"ax\"><rect x=\"" + px(kLeft) + "\" y=\"" + px(kTop) + "\" width=\"" + px(kPlotW) +
                   "\" height=\"" + px(kPlotH) + "\" class=\"f\"/>";
  if (p.categorical) {
    for (std::size_t c = 0; c < nx; ++c)
      ax += "<text x=\"" + px(X(ex[c] + 0.5)) + "\" y=\"" + px(kTop + kPlotH + 16) + "\" text-anchor=\"middle\">" +
            num(p.xs[c], p.xs[c] == std::round(p.xs[c]) ? 0 : 2) + "</text>";
    for (std::size_t r = 0; r < ny; ++r)
      ax += "<text x=\"" + px(kLeft - 6) + "\" y=\"" + px(Y(ey[r] + 0.5) + 4) + "\" text-anchor=\"end\">" +
            num(p.ys[r], p.ys[r] == std::round(p.ys[r]) ? 0 : 2) + "</text>";
  } else {
    Range tx = xr, ty = yr;
    auto xt = ticks(tx), yt = ticks(ty);
    const int xd = decimals_of(xt), yd = decimals_of(yt);
    for (double t : xt)
      if (t >= xr.lo - 1e-9 && t <= xr.hi + 1e-9)
        ax += "<text x=\"" + px(X(t)) + "\" y=\"" + px(kTop + kPlotH + 16) + "\" text-anchor=\"middle\">" + num(t, xd) + "</text>";
    for (double t : yt)
      if (t >= yr.lo - 1e-9 && t <= yr.hi + 1e-9)
        ax += "<text x=\"" + px(kLeft - 6) + "\" y=\"" + px(Y(t) + 4) + "\" text-anchor=\"end\">" + num(t, yd) + "</text>";
  }
  ax += "<text x=\"" + px(kLeft + kPlotW / 2) + "\" y=\"" + px(kH - 12) + "\" text-anchor=\"middle\" class=\"l\">" +
        escape_xml(p.x_label) + "</text><text transform=\"translate(16 " + px(kTop + kPlotH / 2) +
        ") rotate(-90)\" text-anchor=\"middle\" class=\"l\">" + escape_xml(p.y_label) + "</text></g>";
  out += ax;
  // Iso-lines, each labelled at the middle of its longest segment.
  for (const auto& line : p.lines) {
    std::string path, label;
    double longest = -1;
    for (const auto& s : line.segments) {
      path += "M" + px(X(s[0][0])) + " " + px(Y(s[0][1])) + "L" + px(X(s[1][0])) + " " + px(Y(s[1][1]));
      const double len = std::hypot(X(s[1][0]) - X(s[0][0]), Y(s[1][1]) - Y(s[0][1]));
      if (len > longest) {
        longest = len;
        label = "<text x=\"" + px((X(s[0][0]) + X(s[1][0])) / 2) + "\" y=\"" + px((Y(s[0][1]) + Y(s[1][1])) / 2 - 3) +
                "\" text-anchor=\"middle\" class=\"iso-label\">" + percent(line.level) + "</text>";
      }
    }
    out += "<g class=\"iso\" data-level=\"" + num(line.level, 4) + "\"><path d=\"" + path +
           "\" fill=\"none\" stroke=\"#111\" stroke-width=\"1.2\"/>" + label + "</g>";
  }
  // Colour scale.
  out += "<g class=\"scale\">";
  for (int i = 0; i < 20; ++i) {
    const double t = (i + 0.5) / 20;
    out += "<rect x=\"" + px(kW - kRight + 20) + "\" y=\"" + px(kTop + kPlotH * (1 - (i + 1) / 20.0)) +
           "\" width=\"16\" height=\"" + px(kPlotH / 20 + 0.3) + "\" fill=\"" + colour(t) + "\"/>";
  }
  out += "<text x=\"" + px(kW - kRight + 40) + "\" y=\"" + px(kTop + 8) + "\">" + num(z.hi * 100, 1) + " %</text>";
  out += "<text x=\"" + px(kW - kRight + 40) + "\" y=\"" + px(kTop + kPlotH) + "\">" + num(z.lo * 100, 1) + " %</text>";
  out += "<text x=\"" + px(kW - kRight + 20) + "\" y=\"" + px(kTop - 6) + "\">η</text></g>";
  return out + "</svg>";
}

}  // namespace synbench::report
