// The report's uncertainty parts (app/report/report_uncertainty.hpp, svg_plot's error bars) on a
// hand-made analysis JSON: u printed with two significant digits, significance yes / no / unknown,
// the counts of significant differences of those known, the deltas table and the u grid from the
// JSON, "No uncertainty stored" without u, and error bars of +/- 2u in the SVG.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

#include "app/report/report_uncertainty.hpp"
#include "app/report/svg_plot.hpp"
#include "drivers/json.hpp"

namespace synbench::report {
namespace {

db::PointRow row_with_u(std::optional<double> u) {
  db::PointRow r;
  r.record.pdcm_u_W = u;
  return r;
}

Json analysis() {
  return Json::parse(R"({
    "curves": {"entries": [
      {"estimator": "encoder", "pwm": "capwm", "speed_rpm": 300, "load_Nm": 1, "me_minus_mtpa_significant": true},
      {"estimator": "encoder", "pwm": "capwm", "speed_rpm": 300, "load_Nm": 2, "me_minus_mtpa_significant": false},
      {"estimator": "encoder", "pwm": "capwm", "speed_rpm": 600, "load_Nm": 1, "me_minus_mtpa_significant": null}]},
    "deltas": {"entries": [
      {"estimator": "encoder", "pwm": "aspwm", "speed_rpm": 300, "load_Nm": 1,
       "mtpa": {"delta_angle_deg": 0.5, "delta_angle_u_deg": 0.2, "delta_angle_significant": true,
                "delta_im_A": 0.0123, "delta_im_u_A": 0.00456, "delta_im_significant": true},
       "me": {"delta_angle_deg": -0.1, "delta_angle_u_deg": 0.3, "delta_angle_significant": false,
              "delta_pdcm_W": 0.25, "delta_pdcm_u_W": null, "delta_pdcm_significant": null}}]},
    "efficiency_map": {"entries": [
      {"estimator": "encoder", "pwm": "capwm", "speeds_rpm": [300, 600], "loads_Nm": [1, 2],
       "efficiency": [[0.8, 0.81], [0.85, null]], "efficiency_u": [[0.0012, 0.013], [0.00099, null]]}]},
    "uncertainty": {"description": "Monte Carlo over the repeat parts."}
  })");
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(ReportUncertainty, UTextHasTwoSignificantDigits) {
  EXPECT_EQ(u_text(0.013), "0.013");
  EXPECT_EQ(u_text(0.0012345), "0.0012");
  EXPECT_EQ(u_text(1.234), "1.2");
  EXPECT_EQ(u_text(12.34), "12");
  EXPECT_EQ(u_text(0), "0");
  EXPECT_EQ(u_text(std::nan("")), "–");
  EXPECT_EQ(u_text(-1), "–");
  EXPECT_EQ(significance_text(true), "yes");
  EXPECT_EQ(significance_text(false), "no");
  EXPECT_EQ(significance_text(std::nullopt), "–");
}

TEST(ReportUncertainty, JsonReadersTreatNullAsUnknown) {
  const Json a = analysis();
  const Json& d = a["deltas"]["entries"][0];
  EXPECT_DOUBLE_EQ(json_number(d["mtpa"], "delta_im_u_A"), 0.00456);
  EXPECT_TRUE(std::isnan(json_number(d["me"], "delta_pdcm_u_W")));
  EXPECT_TRUE(std::isnan(json_number(d["me"], "no_such_key")));
  EXPECT_EQ(json_bool(d["mtpa"], "delta_im_significant"), std::optional<bool>(true));
  EXPECT_EQ(json_bool(d["me"], "delta_pdcm_significant"), std::nullopt);
}

TEST(ReportUncertainty, SectionCountsTheSignificantOfTheKnown) {
  const std::vector<db::PointRow> rows = {row_with_u(0.1), row_with_u(0.2), row_with_u(std::nullopt)};
  const std::string s = uncertainty_section(analysis(), rows);
  EXPECT_NE(s.find("2 of 3 points carry a standard uncertainty"), std::string::npos) << s;
  EXPECT_NE(s.find("ME angle − MTPA angle (per curve)</th><td>1 of 2</td>"), std::string::npos) << s;
  EXPECT_NE(s.find("ΔI_m on the MTPA trajectory vs reference</th><td>1 of 1</td>"), std::string::npos) << s;
  EXPECT_NE(s.find("Δ ME angle vs reference</th><td>0 of 1</td>"), std::string::npos) << s;
  EXPECT_NE(s.find("ΔP_dcM on the ME trajectory vs reference</th><td>0 of 0</td>"), std::string::npos) << s;
  EXPECT_NE(s.find("Monte Carlo over the repeat parts."), std::string::npos);
  EXPECT_NE(s.find("docs/uncertainty.md"), std::string::npos);
  EXPECT_EQ(s.find("No uncertainty stored"), std::string::npos);
}

TEST(ReportUncertainty, NoUncertaintyStoredWithoutU) {
  const std::string s = uncertainty_section(analysis(), {row_with_u(std::nullopt), row_with_u(std::nullopt)});
  EXPECT_NE(s.find("No uncertainty stored"), std::string::npos);
  EXPECT_EQ(s.find("id=\"significance\""), std::string::npos);
  EXPECT_NE(s.find("docs/uncertainty.md"), std::string::npos);
}

TEST(ReportUncertainty, DeltasTableAndUGridFromTheJson) {
  const std::string t = deltas_table(analysis());
  EXPECT_NE(t.find("<td>encoder</td><td>aspwm</td><td>300</td><td>1</td><td>0.50</td><td>0.20</td><td>yes</td>"
                   "<td>0.012</td><td>0.0046</td><td>yes</td><td>-0.10</td><td>0.30</td><td>no</td><td>0.25</td><td>–</td><td>–</td>"),
            std::string::npos)
      << t;
  EXPECT_EQ(deltas_table(Json::parse(R"({"deltas": {"entries": []}})")), "");
  const std::string g = efficiency_u_grids(analysis());
  EXPECT_NE(g.find("class=\"eta-u-grid\" data-estimator=\"encoder\" data-pwm=\"capwm\""), std::string::npos);
  EXPECT_NE(g.find("<tr><th>300</th><td>0.0012</td><td>0.013</td></tr><tr><th>600</th><td>0.00099</td><td>–</td></tr>"),
            std::string::npos)
      << g;
}

TEST(ReportUncertainty, ErrorBarsAreTwoUAndOnlyWhereUIsKnown) {
  XYPlot p{"t — sweep", "x", "y", {}};
  XYSeries s{"s", {{0, 10}, {1, 20}, {2, 15}}, false};
  s.u = {0.5, std::nan(""), 1.0};
  s.hollow = {false, true, false};
  p.series.push_back(s);
  p.note = "bars: ±2u, 95 %";
  const std::string svg = svg_xy(p);
  EXPECT_EQ(count(svg, "class=\"eb\""), 2u);
  EXPECT_EQ(count(svg, "class=\"insignificant\""), 1u);
  EXPECT_NE(svg.find("data-u=\"0.500000000\""), std::string::npos);
  EXPECT_NE(svg.find("bars: ±2u, 95 %"), std::string::npos);
  // The bar of u = 1 is twice as long as that of u = 0.5: both are +/- 2u on one axis.
  std::regex eb("class=\"eb\" data-u=\"[0-9.]+\" x1=\"[0-9.]+\" y1=\"([0-9.]+)\" x2=\"[0-9.]+\" y2=\"([0-9.]+)\"");
  std::vector<double> len;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), eb); it != std::sregex_iterator(); ++it)
    len.push_back(std::stod((*it)[1].str()) - std::stod((*it)[2].str()));
  ASSERT_EQ(len.size(), 2u);
  EXPECT_NEAR(len[1] / len[0], 2.0, 0.02);
}

}  // namespace
}  // namespace synbench::report
