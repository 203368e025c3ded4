// CSV form of an analysis: one row per (configuration, speed, load) curve with its MTPA and ME
// optima, the reference deltas and the position-error summary, so a spreadsheet user gets the
// trajectories of Figs. 6.8 to 6.15 and 6.21 in one table. Empty cells where a value does not
// exist (no delta for the reference, no position error for the encoder).
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include "bench/analysis.hpp"

namespace synbench::bench {
namespace {

using Key = std::tuple<Configuration, double, double>;

std::string cell(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}
std::string cell(const std::optional<double>& v) { return v ? cell(*v) : std::string(); }
std::string cell(const std::optional<bool>& v) { return v ? (*v ? "1" : "0") : ""; }

}  // namespace

std::string analysis_curves_csv(const Analysis& a) {
  std::map<Key, const DeltaResult*> deltas;
  for (const auto& d : a.deltas) deltas[{d.configuration, d.speed_rpm, d.load_Nm}] = &d;
  std::map<Key, const PositionErrorResult*> pos;
  for (const auto& p : a.position_error) pos[{p.configuration, p.speed_rpm, p.load_Nm}] = &p;

  std::ostringstream o;
  o << "estimator,pwm,speed_rpm,load_Nm,points,"
       "mtpa_angle_deg,mtpa_im_A,mtpa_pdcm_W,mtpa_refined,me_angle_deg,me_im_A,me_pdcm_W,me_pm_W,me_efficiency,me_refined,"
       "mtpa_delta_angle_deg,mtpa_delta_im_A,mtpa_delta_pdcm_W,me_delta_angle_deg,me_delta_im_A,me_delta_pdcm_W,"
       "pos_err_min_deg,pos_err_mean_deg,pos_err_max_deg,"
       "mtpa_angle_u_deg,mtpa_im_u_A,mtpa_pdcm_u_W,me_angle_u_deg,me_im_u_A,me_pdcm_u_W,me_pm_u_W,me_efficiency_u,"
       "me_efficiency_u_repeat,me_minus_mtpa_deg,me_minus_mtpa_u_deg,me_minus_mtpa_significant,"
       "mtpa_delta_angle_u_deg,mtpa_delta_im_u_A,mtpa_delta_pdcm_u_W,mtpa_delta_angle_significant,"
       "mtpa_delta_im_significant,mtpa_delta_pdcm_significant,me_delta_angle_u_deg,me_delta_im_u_A,me_delta_pdcm_u_W,"
       "me_delta_angle_significant,me_delta_im_significant,me_delta_pdcm_significant\n";
  for (const auto& c : a.curves) {
    const Key k{c.configuration, c.speed_rpm, c.load_Nm};
    o << drivers::name(c.configuration.estimator) << ',' << drivers::name(c.configuration.pwm) << ',' << cell(c.speed_rpm)
      << ',' << cell(c.load_Nm) << ',' << c.points << ',' << cell(c.mtpa.angle_deg) << ',' << cell(c.mtpa.im_A) << ','
      << cell(c.mtpa.pdcm_W) << ',' << (c.mtpa.refined ? 1 : 0) << ',' << cell(c.me.angle_deg) << ',' << cell(c.me.im_A)
      << ',' << cell(c.me.pdcm_W) << ',' << cell(c.me.pm_W) << ','
      << (c.me.pdcm_W > 0 ? cell(c.me.efficiency) : std::string()) << ',' << (c.me.refined ? 1 : 0);
    if (auto it = deltas.find(k); it != deltas.end()) {
      const auto& d = *it->second;
      o << ',' << cell(d.mtpa.delta_angle_deg) << ',' << cell(d.mtpa.delta_im_A) << ',' << cell(d.mtpa.delta_pdcm_W) << ','
        << cell(d.me.delta_angle_deg) << ',' << cell(d.me.delta_im_A) << ',' << cell(d.me.delta_pdcm_W);
    } else {
      o << ",,,,,,";
    }
    if (auto it = pos.find(k); it != pos.end())
      o << ',' << cell(it->second->min_deg) << ',' << cell(it->second->mean_deg) << ',' << cell(it->second->max_deg);
    else
      o << ",,,";
    o << ',' << cell(c.mtpa.angle_u_deg) << ',' << cell(c.mtpa.im_u_A) << ',' << cell(c.mtpa.pdcm_u_W) << ','
      << cell(c.me.angle_u_deg) << ',' << cell(c.me.im_u_A) << ',' << cell(c.me.pdcm_u_W) << ',' << cell(c.me.pm_u_W)
      << ',' << cell(c.me.efficiency_u) << ',' << cell(c.me.efficiency_u_repeat) << ',' << cell(c.me_minus_mtpa_deg)
      << ',' << cell(c.me_minus_mtpa_u_deg) << ',' << cell(c.me_minus_mtpa_significant);
    if (auto it = deltas.find(k); it != deltas.end()) {
      for (const auto* t : {&it->second->mtpa, &it->second->me})
        o << ',' << cell(t->delta_angle_u_deg) << ',' << cell(t->delta_im_u_A) << ',' << cell(t->delta_pdcm_u_W) << ','
          << cell(t->delta_angle_significant) << ',' << cell(t->delta_im_significant) << ','
          << cell(t->delta_pdcm_significant);
    } else {
      o << ",,,,,,,,,,,,";
    }
    o << '\n';
  }
  return o.str();
}

}  // namespace synbench::bench
