// Efficiency contours on fields whose iso-lines are known in closed form: a plane (straight lines
// at the analytic positions, the field reproduced exactly), a bilinear saddle (both pairings,
// endpoints on the true level curve), a hole (never filled, no line through it), levels outside
// the data (no lines), the "nice" levels, and the JSON section the REST API serves.
#include "bench/efficiency_contours.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "bench/analysis.hpp"
#include "drivers/json.hpp"

namespace synbench::bench {
namespace {

constexpr double kA = 0.55, kB = 2e-4, kC = 0.04;  // eta = a + b speed + c load
double plane(double s, double l) { return kA + kB * s + kC * l; }

MeasuredGrid planar_grid() {
  MeasuredGrid g;
  g.speed_rpm = {100, 300, 500, 700, 900};
  g.load_Nm = {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5};
  for (double l : g.load_Nm) {
    g.values.emplace_back();
    for (double s : g.speed_rpm) g.values.back().push_back(plane(s, l));
  }
  return g;
}

TEST(EfficiencyContours, PlanarFieldGivesStraightLinesAtTheAnalyticPositions) {
  ContourOptions o;
  o.step = 0.02;
  const auto c = contours_of(planar_grid(), o);
  ASSERT_EQ(c.speed_rpm.size(), 17u);  // 4 intervals x 4 + 1
  ASSERT_EQ(c.load_Nm.size(), 25u);
  EXPECT_DOUBLE_EQ(c.speed_rpm.front(), 100);
  EXPECT_DOUBLE_EQ(c.speed_rpm.back(), 900);  // no extrapolation beyond the measured range
  for (std::size_t r = 0; r < c.load_Nm.size(); ++r)
    for (std::size_t k = 0; k < c.speed_rpm.size(); ++k) {
      ASSERT_TRUE(c.efficiency[r][k].has_value());
      EXPECT_NEAR(*c.efficiency[r][k], plane(c.speed_rpm[k], c.load_Nm[r]), 1e-12);
    }
  // Data from 0.59 to 0.87: levels 0.60 .. 0.86 every 0.02.
  ASSERT_EQ(c.levels.size(), 14u);
  EXPECT_NEAR(c.levels.front(), 0.60, 1e-12);
  EXPECT_NEAR(c.levels.back(), 0.86, 1e-12);
  ASSERT_EQ(c.lines.size(), c.levels.size());
  for (const auto& line : c.lines) {
    ASSERT_FALSE(line.segments.empty());
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& s : line.segments)
      for (const auto& p : s) {
        // On the analytic line speed = (level - a - c load) / b, to rounding.
        EXPECT_NEAR(p[0], (line.level - kA - kC * p[1]) / kB, 1e-6) << "level " << line.level;
        lo = std::min(lo, p[1]);
        hi = std::max(hi, p[1]);
      }
    // The line runs across the field wherever its analytic position is inside the speed range.
    const double l_at_100 = (line.level - kA - kB * 100) / kC, l_at_900 = (line.level - kA - kB * 900) / kC;
    EXPECT_NEAR(lo, std::max(0.5, std::min(l_at_100, l_at_900)), 1e-9) << "level " << line.level;
    EXPECT_NEAR(hi, std::min(3.5, std::max(l_at_100, l_at_900)), 1e-9) << "level " << line.level;
  }
}

MeasuredGrid saddle() {  // eta = 1 - x - y + 2xy on the unit square
  MeasuredGrid g;
  g.speed_rpm = {0, 1};
  g.load_Nm = {0, 1};
  g.values = {{1.0, 0.0}, {0.0, 1.0}};
  return g;
}

TEST(EfficiencyContours, SaddleIsResolvedByTheCentreValue) {
  ContourOptions o;
  o.subdivisions = 1;
  o.levels = {0.4, 0.6};
  const auto c = contours_of(saddle(), o);
  ASSERT_EQ(c.lines.size(), 2u);
  // Endpoints in either order, to rounding.
  const auto same = [](const ContourSegment& s, const ContourSegment& t) {
    const auto eq = [](const ContourPoint& a, const ContourPoint& b) {
      return std::fabs(a[0] - b[0]) < 1e-12 && std::fabs(a[1] - b[1]) < 1e-12;
    };
    return (eq(s[0], t[0]) && eq(s[1], t[1])) || (eq(s[0], t[1]) && eq(s[1], t[0]));
  };
  // 0.4 < centre 0.5: the high corners (0,0) and (1,1) are joined, the low ones cut off.
  ASSERT_EQ(c.lines[0].segments.size(), 2u);
  EXPECT_TRUE(same(c.lines[0].segments[0], ContourSegment{{{0.6, 0.0}, {1.0, 0.4}}}));
  EXPECT_TRUE(same(c.lines[0].segments[1], ContourSegment{{{0.0, 0.6}, {0.4, 1.0}}}));
  // 0.6 > centre: the high corners are cut off.
  ASSERT_EQ(c.lines[1].segments.size(), 2u);
  EXPECT_TRUE(same(c.lines[1].segments[0], ContourSegment{{{0.0, 0.4}, {0.4, 0.0}}}));
  EXPECT_TRUE(same(c.lines[1].segments[1], ContourSegment{{{1.0, 0.6}, {0.6, 1.0}}}));

  // Refined: every endpoint lies on the bilinear field's own level curve (linear along edges).
  o.subdivisions = 8;
  const auto f = contours_of(saddle(), o);
  ASSERT_EQ(f.lines.size(), 2u);
  for (const auto& line : f.lines) {
    EXPECT_GE(line.segments.size(), 8u);
    for (const auto& s : line.segments)
      for (const auto& p : s) EXPECT_NEAR(1 - p[0] - p[1] + 2 * p[0] * p[1], line.level, 1e-12);
  }
}

TEST(EfficiencyContours, HolesStayHolesAndNoLineCrossesThem) {
  auto g = planar_grid();
  g.values[6][4].reset();  // 900 rpm, 3.5 N m not measured: the cell 700..900 x 3.0..3.5 is a hole
  g.values[0][0].reset();  // 100 rpm, 0.5 N m: the cell 100..300 x 0.5..1.0 too
  ContourOptions o;
  o.step = 0.01;
  const auto c = contours_of(g, o);
  const auto in_hole = [](double s, double l) {
    return (s > 700 && l > 3.0) || (s < 300 && l < 1.0);
  };
  std::size_t holes = 0;
  for (std::size_t r = 0; r < c.load_Nm.size(); ++r)
    for (std::size_t k = 0; k < c.speed_rpm.size(); ++k) {
      const double s = c.speed_rpm[k], l = c.load_Nm[r];
      if (in_hole(s, l) || (s == 900 && l == 3.5) || (s == 100 && l == 0.5)) {
        EXPECT_FALSE(c.efficiency[r][k].has_value()) << s << " rpm " << l << " N m";
        ++holes;
      } else {
        ASSERT_TRUE(c.efficiency[r][k].has_value()) << s << " rpm " << l << " N m";
        EXPECT_NEAR(*c.efficiency[r][k], plane(s, l), 1e-12);
      }
    }
  EXPECT_EQ(holes, 2u * 16u);  // each hole: 4 x 4 refined points not on a complete cell's edge
  ASSERT_FALSE(c.lines.empty());
  for (const auto& line : c.lines)
    for (const auto& s : line.segments) {
      const double ms = (s[0][0] + s[1][0]) / 2, ml = (s[0][1] + s[1][1]) / 2;
      EXPECT_FALSE(in_hole(ms, ml)) << "level " << line.level << " crosses a hole at " << ms << ", " << ml;
    }
}

TEST(EfficiencyContours, LevelsOutsideTheDataGiveNoLines) {
  ContourOptions o;
  o.levels = {0.1, 0.5, 0.95, 2.0};
  const auto c = contours_of(planar_grid(), o);
  EXPECT_TRUE(c.levels.empty());
  EXPECT_TRUE(c.lines.empty());
  EXPECT_FALSE(c.efficiency.empty());  // the field is still there
}

TEST(EfficiencyContours, NiceLevelsLieStrictlyInsideTheData) {
  const auto l = contour_levels(0.613, 0.872, {});
  ASSERT_FALSE(l.empty());
  EXPECT_NEAR(l[1] - l[0], 0.05, 1e-12);  // (0.872 - 0.613) / 6 = 0.043 -> 0.05
  EXPECT_NEAR(l.front(), 0.65, 1e-12);
  EXPECT_NEAR(l.back(), 0.85, 1e-12);
  EXPECT_TRUE(contour_levels(0.8, 0.8, {}).empty());
  EXPECT_EQ(contour_levels(0.60, 0.70, {.levels = {}, .step = 0.02, .subdivisions = 4}).size(), 4u);  // .62 .. .68
}

TEST(EfficiencyContours, AnalysisJsonCarriesTheField) {
  Analysis a;
  const Configuration cfg{drivers::Estimator::encoder, drivers::Pwm::capwm};
  const auto g = planar_grid();
  for (std::size_t r = 0; r < g.load_Nm.size(); ++r)
    for (std::size_t k = 0; k < g.speed_rpm.size(); ++k)
      a.efficiency.push_back({cfg, g.speed_rpm[k], g.load_Nm[r], 50, 100 * *g.values[r][k], 100, *g.values[r][k], true, {}, {}, {}, {}});
  a.efficiency_contours = efficiency_contours(a.efficiency, {.levels = {}, .step = 0.05, .subdivisions = 2});
  const auto j = to_json(a);
  const auto& e = j.at("efficiency_contours").at("entries");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].at("estimator"), "encoder");
  EXPECT_EQ(e[0].at("speed_rpm").size(), 9u);
  EXPECT_EQ(e[0].at("load_Nm").size(), 13u);
  EXPECT_EQ(e[0].at("efficiency").size(), 13u);  // rows = load
  EXPECT_EQ(e[0].at("efficiency")[0].size(), 9u);
  EXPECT_NEAR(e[0].at("efficiency")[12][8].get<double>(), plane(900, 3.5), 1e-12);
  ASSERT_EQ(e[0].at("levels").size(), 6u);  // 0.60 .. 0.85
  const auto& seg = e[0].at("lines")[0].at("segments")[0];
  EXPECT_NEAR(seg[0][0].get<double>(), (e[0].at("lines")[0].at("level").get<double>() - kA - kC * seg[0][1].get<double>()) / kB, 1e-6);
}

}  // namespace
}  // namespace synbench::bench
