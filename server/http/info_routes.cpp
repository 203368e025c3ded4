// GET /api/whoami, /api/estimators, /api/devices, /api/profiles; see info_routes.hpp.
#include "server/http/info_routes.hpp"

#include <fstream>
#include <sstream>

#include "drivers/profile/device_profile.hpp"
#include "drivers/profile/signal_catalogue.hpp"
#include "server/http/response_schemas.hpp"

namespace synbench::http {
namespace {

// What each position source is and what it needs, for a client choosing one (physics.md 8).
synbench::Json estimators_json(const emulator::TwinConfig& c) {
  const auto& e = c.estimators;
  synbench::Json out = synbench::Json::array();
  const auto add = [&out](drivers::Estimator est, bool sensorless, const char* description, synbench::Json extra) {
    synbench::Json j = {{"name", std::string(drivers::name(est))}, {"sensorless", sensorless}, {"description", description}};
    j.update(extra);
    out.push_back(std::move(j));
  };
  const synbench::Json eemf_range = {{"min_speed_rpm", e.eemf.min_speed_rpm},
                                     {"handover_hysteresis_rpm", e.eemf.handover_hysteresis_rpm},
                                     {"low_speed_source", emulator::kLowSpeedSourceNames[static_cast<std::size_t>(e.eemf.low_speed_source)]}};
  add(drivers::Estimator::encoder, false, "incremental encoder: the reference", {{"min_speed_rpm", 0}});
  add(drivers::Estimator::ekf_basic, true, "EKF on the dq model: angle, speed, Ld, Lq", {{"min_speed_rpm", 0}});
  add(drivers::Estimator::ekf_rs, true, "EKF that also estimates the stator resistance",
      {{"min_speed_rpm", 0}, {"rs_speed_threshold_rpm", e.ekf.rs_speed_threshold_rpm}});
  add(drivers::Estimator::hfi, true, "high-frequency injection (saliency tracking)",
      {{"min_speed_rpm", 0}, {"injection", {{"voltage_V", e.hfi.voltage_V}, {"frequency_Hz", e.hfi.frequency_Hz}}}});
  synbench::Json lut = eemf_range;
  lut["lut_ld_scale"] = e.eemf.lut_ld_scale;
  lut["lut_lq_scale"] = e.eemf.lut_lq_scale;
  synbench::Json cst = eemf_range;
  cst["ld_H"] = e.eemf.ld_H;
  cst["lq_H"] = e.eemf.lq_H;
  synbench::Json rls = eemf_range;
  rls["injection"] = {{"prbs_voltage_V", e.eemf.prbs_voltage_V}, {"prbs_bit_s", e.eemf.prbs_bit_s}};
  add(drivers::Estimator::eemf_const, true, "extended EMF observer, constant inductances", cst);
  add(drivers::Estimator::eemf_lut, true, "extended EMF observer, inductance tables", lut);
  add(drivers::Estimator::eemf_rls, true, "extended EMF observer, inductances by RLS with PRBS injection", rls);
  return out;
}

synbench::Json profiles_json() {
  synbench::Json out = synbench::Json::array();
  for (const auto kind : drivers::kDeviceKinds) {
    const auto file = drivers::default_profile_path(kind);
    synbench::Json j = {{"kind", std::string(drivers::name(kind))}, {"file", file.filename().string()}};
    const auto parsed = drivers::load_device_profile(file);
    if (parsed.profile) {
      std::ifstream in(file);
      std::stringstream text;
      text << in.rdbuf();
      j["valid"] = true;
      j["profile"] = synbench::Json::parse(text.str(), nullptr, false);
    } else {
      j["valid"] = false;
      synbench::Json errors = synbench::Json::array();
      for (const auto& e : parsed.errors) errors.push_back({{"path", e.pointer}, {"reason", e.reason}});
      j["errors"] = errors;
    }
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace

void add_info_routes(Router& router, const BenchRuntime& bench, const emulator::TwinConfig& twin) {
  router.add(answering({"GET", "/api/whoami", Role::viewer, "The caller's role and identity label (never the token).",
                        [](const Request& req) { return json_response(200, {{"role", role_name(req.caller)}, {"id", req.caller_id}}); }},
                       whoami_schema()));
  const synbench::Json estimators = estimators_json(twin);
  router.add(answering({"GET", "/api/estimators", Role::viewer,
                        "Position sources the SynRM drive offers (POST /api/bench/mode selects one), with their speed ranges.",
                        [estimators](const Request&) { return json_response(200, estimators); }},
                       estimators_schema()));
  router.add({"GET", "/api/devices", Role::viewer, "The bench's devices: role, kind, backend, link, profile.",
              [devices = bench.devices_json()](const Request&) { return json_response(200, devices); }});
  router.add({"GET", "/api/profiles", Role::viewer, "The default device profiles (docs/device-profile.md), as loaded.",
              [](const Request&) { return json_response(200, profiles_json()); }});
}

}  // namespace synbench::http
