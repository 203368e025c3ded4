// Bilinear field and marching-squares iso-lines of the efficiency map; see efficiency_contours.hpp.
#include "bench/efficiency_contours.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <set>

#include "bench/analysis.hpp"
#include "bench/efficiency_grid.hpp"

namespace synbench::bench {
namespace {

using Field = std::vector<std::vector<std::optional<double>>>;

// The refined axis: `sub` equal steps inside each measured interval. cell[k] and frac[k] say
// where refined point k lies: measured interval cell[k] at fraction frac[k] in [0, 1].
struct RefinedAxis {
  std::vector<double> at;
  std::vector<std::size_t> cell;
  std::vector<double> frac;
};

RefinedAxis refine(const std::vector<double>& axis, int sub) {
  RefinedAxis r;
  for (std::size_t i = 0; i + 1 < axis.size(); ++i)
    for (int k = 0; k < sub; ++k) {
      const double t = static_cast<double>(k) / static_cast<double>(sub);
      r.at.push_back(axis[i] + (axis[i + 1] - axis[i]) * t);
      r.cell.push_back(i);
      r.frac.push_back(t);
    }
  r.at.push_back(axis.back());
  r.cell.push_back(axis.size() - 2);
  r.frac.push_back(1.0);
  return r;
}

// The measured cells a refined point may be read in: its own, and on a measured grid line also
// the one before it (the two agree there: bilinear is linear along a shared edge).
std::vector<std::pair<std::size_t, double>> candidates(const RefinedAxis& a, std::size_t k) {
  std::vector<std::pair<std::size_t, double>> out{{a.cell[k], a.frac[k]}};
  if (a.frac[k] == 0.0 && a.cell[k] > 0) out.emplace_back(a.cell[k] - 1, 1.0);
  return out;
}

std::optional<double> bilinear(const MeasuredGrid& g, std::size_t row, double ty, std::size_t col, double tx) {
  const auto& v00 = g.values[row][col];
  const auto& v01 = g.values[row][col + 1];
  const auto& v10 = g.values[row + 1][col];
  const auto& v11 = g.values[row + 1][col + 1];
  if (!v00 || !v01 || !v10 || !v11) return std::nullopt;  // a hole: never filled in
  return (1 - tx) * (1 - ty) * *v00 + tx * (1 - ty) * *v01 + (1 - tx) * ty * *v10 + tx * ty * *v11;
}

ContourPoint crossing(const ContourPoint& p1, double v1, const ContourPoint& p2, double v2, double level) {
  const double t = (level - v1) / (v2 - v1);
  return {p1[0] + t * (p2[0] - p1[0]), p1[1] + t * (p2[1] - p1[1])};
}

// Marching squares over the field's cells whose four corners have values; the two saddle cases
// are told apart by the cell's centre value.
std::vector<ContourSegment> march(const std::vector<double>& xs, const std::vector<double>& ys, const Field& f,
                                  double level) {
  std::vector<ContourSegment> out;
  const auto add = [&out](const ContourPoint& a, const ContourPoint& b) {
    if (a != b) out.push_back({a, b});
  };
  for (std::size_t r = 0; r + 1 < ys.size(); ++r)
    for (std::size_t c = 0; c + 1 < xs.size(); ++c) {
      const auto& a0 = f[r][c];
      const auto& b0 = f[r][c + 1];
      const auto& c0 = f[r + 1][c + 1];
      const auto& d0 = f[r + 1][c];
      if (!a0 || !b0 || !c0 || !d0) continue;
      const double va = *a0, vb = *b0, vc = *c0, vd = *d0;
      const ContourPoint pa{xs[c], ys[r]}, pb{xs[c + 1], ys[r]}, pc{xs[c + 1], ys[r + 1]}, pd{xs[c], ys[r + 1]};
      const bool ua = va >= level, ub = vb >= level, uc = vc >= level, ud = vd >= level;
      // Edges in order bottom (a-b), right (b-c), top (d-c), left (a-d).
      std::optional<ContourPoint> e[4];
      if (ua != ub) e[0] = crossing(pa, va, pb, vb, level);
      if (ub != uc) e[1] = crossing(pb, vb, pc, vc, level);
      if (ud != uc) e[2] = crossing(pd, vd, pc, vc, level);
      if (ua != ud) e[3] = crossing(pa, va, pd, vd, level);
      const int n = (e[0] ? 1 : 0) + (e[1] ? 1 : 0) + (e[2] ? 1 : 0) + (e[3] ? 1 : 0);
      if (n == 2) {
        std::vector<ContourPoint> p;
        for (const auto& x : e)
          if (x) p.push_back(*x);
        add(p[0], p[1]);
      } else if (n == 4) {
        const bool centre_up = (va + vb + vc + vd) / 4 >= level;
        if (centre_up == ua) {  // a and c joined through the centre: b and d cut off
          add(*e[0], *e[1]);
          add(*e[2], *e[3]);
        } else {  // a and c cut off
          add(*e[3], *e[0]);
          add(*e[1], *e[2]);
        }
      }
    }
  return out;
}

}  // namespace

std::vector<double> contour_levels(double lo, double hi, const ContourOptions& options) {
  std::vector<double> out;
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi < lo) return out;
  if (!options.levels.empty()) {
    for (double l : options.levels)
      if (l >= lo && l <= hi) out.push_back(l);
    std::sort(out.begin(), out.end());
    return out;
  }
  if (hi <= lo) return out;
  double step = options.step;
  if (!(step > 0)) {
    const double raw = (hi - lo) / 6;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double norm = raw / mag;
    step = (norm < 1.5 ? 1 : norm < 3.5 ? 2 : norm < 7.5 ? 5 : 10) * mag;
  }
  // Strictly inside the data: a level at the extreme value only touches it.
  const double eps = step * 1e-9;
  const auto first = static_cast<long long>(std::ceil((lo + eps) / step));
  const auto last = static_cast<long long>(std::floor((hi - eps) / step));
  for (long long k = first; k <= last && out.size() < 200; ++k) out.push_back(static_cast<double>(k) * step);
  return out;
}

EfficiencyContours contours_of(const MeasuredGrid& g, const ContourOptions& options) {
  EfficiencyContours out;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& row : g.values)
    for (const auto& v : row)
      if (v) {
        lo = std::min(lo, *v);
        hi = std::max(hi, *v);
      }
  if (g.speed_rpm.size() < 2 || g.load_Nm.size() < 2) {  // no cell to interpolate in
    out.speed_rpm = g.speed_rpm;
    out.load_Nm = g.load_Nm;
    out.efficiency = g.values;
    out.levels = contour_levels(lo, hi, options);
    return out;
  }
  const int sub = std::max(1, options.subdivisions);
  const RefinedAxis xs = refine(g.speed_rpm, sub), ys = refine(g.load_Nm, sub);
  out.speed_rpm = xs.at;
  out.load_Nm = ys.at;
  out.efficiency.assign(ys.at.size(), std::vector<std::optional<double>>(xs.at.size()));
  for (std::size_t r = 0; r < ys.at.size(); ++r)
    for (std::size_t c = 0; c < xs.at.size(); ++c)
      for (const auto& [row, ty] : candidates(ys, r)) {
        for (const auto& [col, tx] : candidates(xs, c))
          if (auto v = bilinear(g, row, ty, col, tx)) {
            out.efficiency[r][c] = v;
            break;
          }
        if (out.efficiency[r][c]) break;
      }
  out.levels = contour_levels(lo, hi, options);
  for (double level : out.levels) {
    ContourLine line{level, march(out.speed_rpm, out.load_Nm, out.efficiency, level)};
    if (!line.segments.empty()) out.lines.push_back(std::move(line));
  }
  return out;
}

MeasuredGrid measured_efficiency_grid(const std::vector<EfficiencyCell>& cells, const Configuration& configuration) {
  return measured_efficiency_grid(cells, configuration, nullptr);
}

MeasuredGrid measured_efficiency_grid(const std::vector<EfficiencyCell>& cells, const Configuration& configuration,
                                      std::optional<double> EfficiencyCell::*field) {
  const auto add = [](std::vector<double>& v, double x) {
    for (double y : v)
      if (std::fabs(y - x) < 1e-6) return;
    v.push_back(x);
  };
  const auto index = [](const std::vector<double>& v, double x) {
    std::size_t i = 0;
    while (std::fabs(v[i] - x) >= 1e-6) ++i;
    return i;
  };
  MeasuredGrid g;
  for (const auto& c : cells)
    if (c.configuration == configuration) {
      add(g.speed_rpm, c.speed_rpm);
      add(g.load_Nm, c.load_Nm);
    }
  std::sort(g.speed_rpm.begin(), g.speed_rpm.end());
  std::sort(g.load_Nm.begin(), g.load_Nm.end());
  g.values.assign(g.load_Nm.size(), std::vector<std::optional<double>>(g.speed_rpm.size()));
  for (const auto& c : cells)
    if (c.configuration == configuration && c.pdcm_W > 0 && std::isfinite(c.efficiency))
      g.values[index(g.load_Nm, c.load_Nm)][index(g.speed_rpm, c.speed_rpm)] =
          field ? c.*field : std::optional<double>(c.efficiency);
  return g;
}

std::vector<EfficiencyContours> efficiency_contours(const std::vector<EfficiencyCell>& cells,
                                                    const ContourOptions& options) {
  std::set<Configuration> configs;
  for (const auto& c : cells) configs.insert(c.configuration);
  std::vector<EfficiencyContours> out;
  for (const auto& config : configs) {
    out.push_back(contours_of(measured_efficiency_grid(cells, config), options));
    out.back().configuration = config;
  }
  return out;
}

}  // namespace synbench::bench
