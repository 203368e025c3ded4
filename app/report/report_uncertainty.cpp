// The report's uncertainty section and tables; see report_uncertainty.hpp.
#include "app/report/report_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/report/report_text.hpp"
#include "app/report/svg_plot.hpp"
#include "drivers/json.hpp"

namespace synbench::report {
namespace {

using Json = synbench::Json;

const Json& entries(const Json& a, const char* section) {
  static const Json kEmpty = Json::array();
  const auto s = a.find(section);
  if (s == a.end() || !s->is_object()) return kEmpty;
  const auto e = s->find("entries");
  return e != s->end() && e->is_array() ? *e : kEmpty;
}
const Json& member(const Json& j, const char* key) {
  static const Json kNull;
  const auto it = j.find(key);
  return it == j.end() ? kNull : *it;
}
std::string str(const Json& j, const char* key) {
  const auto& v = member(j, key);
  return v.is_string() ? v.get<std::string>() : std::string();
}

struct Count {
  std::size_t significant = 0, known = 0;
  void add(std::optional<bool> s) {
    if (!s) return;
    ++known;
    if (*s) ++significant;
  }
  std::string text() const { return std::to_string(significant) + " of " + std::to_string(known); }
};

}  // namespace

double json_number(const Json& j, const char* key) {
  if (!j.is_object()) return std::nan("");
  const auto& v = member(j, key);
  return v.is_number() ? v.get<double>() : std::nan("");
}

std::optional<bool> json_bool(const Json& j, const char* key) {
  if (!j.is_object()) return std::nullopt;
  const auto& v = member(j, key);
  return v.is_boolean() ? std::optional<bool>(v.get<bool>()) : std::nullopt;
}

std::string u_text(double u) {
  if (!std::isfinite(u) || u < 0) return "–";
  if (u == 0) return "0";
  const int d = std::max(0, 1 - static_cast<int>(std::floor(std::log10(u))));
  return fixed(u, std::min(d, 8));
}

std::string significance_text(std::optional<bool> s) { return s ? (*s ? "yes" : "no") : "–"; }

std::size_t points_with_u(const std::vector<db::PointRow>& rows) {
  std::size_t n = 0;
  for (const auto& r : rows)
    if (r.record.pdcm_u_W) ++n;
  return n;
}

std::string uncertainty_section(const Json& a, const std::vector<db::PointRow>& rows) {
  std::string b = "\n<h2 id=\"uncertainty\">Uncertainty</h2>\n";
  const std::size_t with_u = points_with_u(rows);
  if (with_u == 0) {
    b += "<p class=\"no-u\">No uncertainty stored: the points of this sweep carry no standard uncertainty (measured before "
         "the record had one, or on devices without batches), so no figure has error bars and no difference is called "
         "significant.</p>\n";
  } else {
    Count me_mtpa, d_angle_mtpa, d_im, d_angle_me, d_pdcm;
    for (const auto& c : entries(a, "curves")) me_mtpa.add(json_bool(c, "me_minus_mtpa_significant"));
    for (const auto& d : entries(a, "deltas")) {
      d_angle_mtpa.add(json_bool(member(d, "mtpa"), "delta_angle_significant"));
      d_im.add(json_bool(member(d, "mtpa"), "delta_im_significant"));
      d_angle_me.add(json_bool(member(d, "me"), "delta_angle_significant"));
      d_pdcm.add(json_bool(member(d, "me"), "delta_pdcm_significant"));
    }
    b += "<p>" + std::to_string(with_u) + " of " + std::to_string(rows.size()) +
         " points carry a standard uncertainty. Values are given as value ± u, the combined standard uncertainty (k = 1); "
         "error bars in the figures show ±2u (about 95 %); hollow markers are differences not significant at 95 %.</p>\n"
         "<table id=\"significance\"><thead><tr><th>difference</th><th>significant at 95 %</th></tr></thead><tbody>";
    const auto row = [&b](const std::string& what, const Count& c) { b += "<tr><th>" + escape_xml(what) + "</th>" + td(c.text()) + "</tr>"; };
    row("ME angle − MTPA angle (per curve)", me_mtpa);
    row("Δ MTPA angle vs reference", d_angle_mtpa);
    row("ΔI_m on the MTPA trajectory vs reference", d_im);
    row("Δ ME angle vs reference", d_angle_me);
    row("ΔP_dcM on the ME trajectory vs reference", d_pdcm);
    b += "</tbody></table>\n";
    const auto& u = member(a, "uncertainty");
    if (u.is_object() && member(u, "description").is_string()) b += "<p>" + escape_xml(str(u, "description")) + "</p>\n";
  }
  b += "<p class=\"u-doc\">The uncertainty budget (type A from batch means, type B of the meter and the sensors, "
       "each with its source) and how the angles and differences propagate it: docs/uncertainty.md.</p>\n";
  return b;
}

std::string deltas_table(const Json& a) {
  const auto& des = entries(a, "deltas");
  if (des.empty()) return "";
  std::string b = "<h3>Deltas against the reference, with u (k = 1) and significance at 95 %</h3>\n"
                  "<table id=\"deltas\"><thead><tr><th>estimator</th><th>pwm</th><th>speed_rpm</th><th>load_Nm</th>"
                  "<th>MTPA delta_angle_deg</th><th>u</th><th>significant</th><th>MTPA delta_im_A</th><th>u</th><th>significant</th>"
                  "<th>ME delta_angle_deg</th><th>u</th><th>significant</th><th>ME delta_pdcm_W</th><th>u</th><th>significant</th>"
                  "</tr></thead><tbody>";
  const auto cell = [](const Json& t, const char* v, const char* u, const char* s, int d) {
    return td(fixed(json_number(t, v), d)) + td(u_text(json_number(t, u))) + td(significance_text(json_bool(t, s)));
  };
  for (const auto& d : des) {
    const auto& m = member(d, "mtpa");
    const auto& e = member(d, "me");
    b += "<tr>" + td(str(d, "estimator")) + td(str(d, "pwm")) + td(shortest(json_number(d, "speed_rpm"))) +
         td(shortest(json_number(d, "load_Nm"))) + cell(m, "delta_angle_deg", "delta_angle_u_deg", "delta_angle_significant", 2) +
         cell(m, "delta_im_A", "delta_im_u_A", "delta_im_significant", 3) +
         cell(e, "delta_angle_deg", "delta_angle_u_deg", "delta_angle_significant", 2) +
         cell(e, "delta_pdcm_W", "delta_pdcm_u_W", "delta_pdcm_significant", 2) + "</tr>";
  }
  return b + "</tbody></table>\n";
}

std::string efficiency_u_grids(const Json& a) {
  std::string b;
  for (const auto& e : entries(a, "efficiency_map")) {
    const auto& u = member(e, "efficiency_u");
    const auto& speeds = member(e, "speeds_rpm");
    const auto& loads = member(e, "loads_Nm");
    if (!u.is_array() || !speeds.is_array() || !loads.is_array()) continue;
    b += "<h3>Standard uncertainty u of the efficiency at the ME angle, speed x load, " + escape_xml(str(e, "estimator")) + "/" +
         escape_xml(str(e, "pwm")) + "</h3>\n<table class=\"eta-u-grid\" data-estimator=\"" + escape_xml(str(e, "estimator")) +
         "\" data-pwm=\"" + escape_xml(str(e, "pwm")) + "\"><thead><tr><th>speed_rpm \\ load_Nm</th>";
    for (const auto& l : loads) b += "<th>" + shortest(l.get<double>()) + "</th>";
    b += "</tr></thead><tbody>";
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      b += "<tr><th>" + shortest(speeds[i].get<double>()) + "</th>";
      for (std::size_t k = 0; k < loads.size(); ++k) {
        const bool has = i < u.size() && u[i].is_array() && k < u[i].size() && u[i][k].is_number();
        b += td(has ? u_text(u[i][k].get<double>()) : "–");
      }
      b += "</tr>";
    }
    b += "</tbody></table>\n";
  }
  return b;
}

}  // namespace synbench::report
