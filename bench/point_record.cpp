// JSON and text forms of a point record.
#include "bench/point_record.hpp"

#include "drivers/json.hpp"

#include <cstdio>
#include <sstream>

namespace synbench::bench {
namespace {

synbench::Json opt(const std::optional<double>& v) {
  return v ? synbench::Json(*v) : synbench::Json(nullptr);
}

}  // namespace

synbench::Json to_json(const PointRecord& r) {
  synbench::Json j = synbench::Json::object();
  j["speed_rpm"] = r.speed_rpm;
  j["load_Nm"] = r.load_Nm;
  j["angle_deg"] = r.angle_deg;
  j["estimator"] = std::string(drivers::name(r.estimator));
  j["pwm"] = std::string(drivers::name(r.pwm));
  j["speed_meas_rpm"] = r.speed_meas_rpm;
  j["im_A"] = r.im_A;
  j["id_A"] = r.id_A;
  j["iq_A"] = r.iq_A;
  j["ud_V"] = r.ud_V;
  j["uq_V"] = r.uq_V;
  j["udc_V"] = r.udc_V;
  j["idcm_A"] = r.idcm_A;
  j["idcg_A"] = r.idcg_A;
  j["pdcm_W"] = r.pdcm_W;
  j["pdcg_W"] = r.pdcg_W;
  j["pm_W"] = r.pm_W;
  j["efficiency"] = r.efficiency;
  j["pos_err_min_deg"] = opt(r.pos_err_min_deg);
  j["pos_err_mean_deg"] = opt(r.pos_err_mean_deg);
  j["pos_err_max_deg"] = opt(r.pos_err_max_deg);
  j["speed_err_rpm"] = opt(r.speed_err_rpm);
  j["ld_est_H"] = opt(r.ld_est_H);
  j["lq_est_H"] = opt(r.lq_est_H);
  j["rs_est_ohm"] = opt(r.rs_est_ohm);
  j["ld_err_pct"] = opt(r.ld_err_pct);
  j["lq_err_pct"] = opt(r.lq_err_pct);
  j["rs_err_pct"] = opt(r.rs_err_pct);
  j["temp_C"] = opt(r.temp_C);
  j["window_s"] = r.window_s;
  j["samples"] = r.samples;
  j["settle_s"] = r.settle_s;
  j["voltage_limited"] = r.voltage_limited;
  j["unstable"] = r.unstable;
  j["fault"] = r.fault ? synbench::Json(*r.fault) : synbench::Json(nullptr);
  j["below_min_speed"] = r.below_min_speed;
  j["fallback_fraction"] = r.fallback_fraction;
  j["lock_lost"] = r.lock_lost;
  j["window_source"] = drivers::keeper_name(r.window_source);
  j["fault_code_raw"] = r.fault_code_raw ? synbench::Json(*r.fault_code_raw) : synbench::Json(nullptr);
  j["angle_meas_deg"] = opt(r.angle_meas_deg);
  j["angle_off"] = r.angle_off;
  if (r.truth) {
    const auto& t = *r.truth;
    j["truth"] = {{"pin_W", t.pin_W},     {"pcu_W", t.pcu_W}, {"pfe_W", t.pfe_W},
                  {"pmech_W", t.pmech_W}, {"pinvm_W", t.pinvm_W}, {"pm_W", t.pm_W},
                  {"temp_C", t.temp_C}};
  } else {
    j["truth"] = nullptr;
  }
  return j;
}

std::string to_text(const PointRecord& r) {
  std::ostringstream s;
  const auto j = to_json(r);
  auto line = [&](const std::string& key, const synbench::Json& v) {
    char buf[64];
    if (v.is_number_float()) {
      std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    } else if (v.is_null()) {
      std::snprintf(buf, sizeof buf, "-");
    } else {
      std::snprintf(buf, sizeof buf, "%s", v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
    }
    s << "  " << key << std::string(key.size() < 18 ? 18 - key.size() : 1, ' ') << buf << "\n";
  };
  for (const auto& [key, v] : j.items())
    if (key != "truth") line(key, v);
  if (r.truth) {
    s << "  truth (plant's own values)\n";
    for (const auto& [key, v] : j["truth"].items()) line("  " + key, v);
  }
  return s.str();
}

}  // namespace synbench::bench
