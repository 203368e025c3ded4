// Route handlers of the daemon; see api_routes.hpp and docs/api.md.
#include "server/http/api_routes.hpp"

#include "server/http/info_routes.hpp"
#include "server/http/instance_id.hpp"

#include "server/http/metrics_text.hpp"
#include "server/http/response_schemas.hpp"

#include "bench/current_angle.hpp"

#include <chrono>
#include <memory>
#include <sstream>

namespace synbench::http {

void HttpMetrics::count(int status) {
  std::lock_guard lock(mutex_);
  ++by_status_[status];
}

std::map<int, std::uint64_t> HttpMetrics::by_status() const {
  std::lock_guard lock(mutex_);
  return by_status_;
}

BenchRuntime::Done answer(Reply reply, int ok_status) {
  // Runs on the bench thread, which has no handler for an exception: guarded makes it a 500.
  return [reply = std::move(reply), ok_status](app::Outcome o) {
    reply(guarded("a bench command's answer", [&] { return outcome_response(o, ok_status); }));
  };
}

namespace {

synbench::Json number_schema(double min, double max, const std::string& desc) {
  return {{"type", "number"}, {"minimum", min}, {"maximum", max}, {"description", desc}};
}

}  // namespace

int http_status(app::Refused r) {
  switch (r) {
    case app::Refused::device_error: return 502;
    case app::Refused::database: return 500;
    case app::Refused::queue_full:
    case app::Refused::shutting_down: return 503;
    default: return 409;
  }
}

Response status_response(const app::StatusSnapshot& s) {
  Response r;
  r.body = s.text;
  return r;
}

Response outcome_response(const app::Outcome& o, int ok_status) {
  if (o.refusal) return error_response(http_status(o.refusal->code), std::string(app::name(o.refusal->code)), o.refusal->message);
  Response r = status_response(*o.snapshot);
  r.status = ok_status;
  return r;
}

Response locked(const ControlLock& lock) {
  const auto d = lock.describe();
  return error_response(409, "locked",
                        "the control lock is held by " + d.value("holder", std::string("another operator")) +
                            " (it expires after " + std::to_string(ControlLock::kIdle.count()) +
                            " s idle; E-stop is always allowed)");
}

const char* phase_name(bench::SafetyPhase p) {
  switch (p) {
    case bench::SafetyPhase::normal: return "normal";
    case bench::SafetyPhase::stopping_load: return "stopping_load";
    case bench::SafetyPhase::stopping_speed: return "stopping_speed";
    case bench::SafetyPhase::stopped: return "stopped";
    case bench::SafetyPhase::estopped: return "estopped";
  }
  return "?";
}

namespace {

// A stop's disable per drive (bench/disable_report.hpp).
synbench::Json disable_json(const bench::DisableReport& r) {
  const auto drive = [](const bench::DriveDisable& d) {
    return synbench::Json{{"state", std::string(bench::name(d.state))},
                          {"first_acknowledged", d.first_acknowledged},
                          {"attempts", d.attempts},
                          {"error", d.error.empty() ? synbench::Json(nullptr) : synbench::Json(d.error)},
                          {"confirmed_s", d.confirmed_s ? synbench::Json(*d.confirmed_s) : synbench::Json(nullptr)},
                          {"setpoint_zeroed", d.setpoint_zeroed}};
  };
  return {{"at_s", r.at_s}, {"confirmed", r.confirmed()}, {"synrm", drive(r.synrm)}, {"load", drive(r.load)}};
}

// A drive's own code of a fault its profile has no label for (fault "unknown"), else null.
synbench::Json raw_code(const std::optional<std::int64_t>& code) {
  return code ? synbench::Json(*code) : synbench::Json(nullptr);
}

}  // namespace

synbench::Json status_json(const BenchStatus& s) {
  synbench::Json j;
  j["t_s"] = s.t_s;
  j["enabled"] = s.enabled;
  j["stopping"] = s.stopping;
  j["heartbeats"] = s.heartbeats;
  j["setpoints"] = {{"speed_rpm", s.setpoints.speed_rpm}, {"load_Nm", s.setpoints.load_Nm}, {"angle_deg", s.setpoints.angle_deg}};
  j["commanded"] = {{"speed_rpm", s.commanded.speed_rpm}, {"load_Nm", s.commanded.load_Nm}, {"angle_deg", s.commanded.angle_deg}};
  j["mode"] = {{"estimator", std::string(drivers::name(s.mode.estimator))}, {"pwm", std::string(drivers::name(s.mode.pwm))}};
  if (s.synrm) {
    const auto& t = *s.synrm;
    j["synrm"] = {{"speed_rpm", t.speed_rpm}, {"im_A", t.im_A},     {"id_A", t.id_A},     {"iq_A", t.iq_A},
                  {"ud_V", t.ud_V},           {"uq_V", t.uq_V},     {"udc_V", t.udc_V},   {"pac_W", t.pac_W},
                  {"temp_C", t.temp_C ? synbench::Json(*t.temp_C) : synbench::Json(nullptr)},       {"voltage_limited", t.voltage_limited}, {"lock_lost", t.lock_lost},
                  {"pos_err_deg", t.pos_err_deg ? synbench::Json(*t.pos_err_deg) : synbench::Json(nullptr)},
                  {"state", drivers::state_name(t.state)}, {"fault", std::string(drivers::fault_name(t.fault))},
                  {"fault_code_raw", raw_code(t.fault_code_raw)}};
  } else {
    j["synrm"] = nullptr;
  }
  if (s.load) {
    const auto& t = *s.load;
    j["load"] = {{"torque_Nm", t.torque_Nm}, {"iq_A", t.iq_A}, {"state", drivers::state_name(t.state)},
                 {"fault", std::string(drivers::fault_name(t.fault))}, {"fault_code_raw", raw_code(t.fault_code_raw)}};
  } else {
    j["load"] = nullptr;
  }
  // A drive that could not be read is null, and the read's error says why (never silently null).
  const auto read_error = [](const std::string& e) { return e.empty() ? synbench::Json(nullptr) : synbench::Json(e); };
  j["synrm_error"] = read_error(s.synrm_error);
  j["load_error"] = read_error(s.load_error);
  j["supervisor"] = {{"phase", phase_name(s.phase)}, {"tripped", s.trip.has_value()}};
  if (s.trip)
    j["supervisor"]["trip"] = {{"fault", std::string(drivers::fault_name(s.trip->fault))},
                               {"fault_code_raw", raw_code(s.trip->fault_code_raw)},
                               {"detail", s.trip->detail},
                               {"at_s", s.trip->at_s}};
  j["supervisor"]["alarm"] = s.alarm ? synbench::Json{{"detail", s.alarm->detail}, {"at_s", s.alarm->at_s}} : synbench::Json(nullptr);
  j["supervisor"]["disable"] = s.disable ? disable_json(*s.disable) : synbench::Json(nullptr);
  j["loop"] = {{"ticks", s.ticks}, {"overruns", s.overruns}};
  if (s.sweep) {
    j["sweep"] = {{"id", s.sweep->id}, {"state", s.sweep->state}, {"done", s.sweep->done}, {"total", s.sweep->total},
                  {"error", s.sweep->error}};
    j["sweep"]["current_index"] = s.sweep->current_index ? synbench::Json(*s.sweep->current_index) : synbench::Json(nullptr);
    if (const auto& p = s.sweep->point)
      j["sweep"]["point"] = {{"speed_rpm", p->speed_rpm}, {"load_Nm", p->load_Nm}, {"angle_deg", p->angle_deg},
                             {"estimator", std::string(drivers::name(p->estimator))}, {"pwm", std::string(drivers::name(p->pwm))}};
    else
      j["sweep"]["point"] = nullptr;
  } else {
    j["sweep"] = nullptr;
  }
  synbench::Json ev = synbench::Json::array();
  for (const auto& e : s.events) ev.push_back({{"t_s", e.t_s}, {"kind", e.kind}, {"message", e.message}});
  j["events"] = ev;
  return j;
}

void add_api_routes(Router& router, ApiContext ctx) {
  BenchRuntime* bench = &ctx.bench;
  HttpMetrics* metrics = &ctx.metrics;
  const Router* self = &router;
  const std::string version = ctx.version;
  const double max_speed_rpm = bench->description().max_speed_rpm;
  const double max_load_Nm = bench->description().max_load_Nm;
  ControlLock* control = &ctx.control;

  add_info_routes(router, *bench, ctx.twin);
  router.add(answering({"GET", "/api/health", Role::anyone, "Liveness: the daemon answers and its bench loop runs; instance changes when the daemon restarts.",
                        [bench, version](const Request&) {
                          const auto snap = bench->snapshot();  // the status lives as long as the snapshot
                          const auto& s = snap->status;
                          return json_response(200, {{"status", "ok"}, {"version", version}, {"instance", instance_id()}, {"bench_time_s", s.t_s}, {"ticks", s.ticks}});
                        }},
                       health_schema()));
  router.add({"GET", "/api/openapi.json", Role::anyone, "This API as an OpenAPI 3 document.",
              [self, version](const Request&) { return json_response(200, self->openapi("synbench", version)); }});
  router.add({"GET", "/metrics", Role::anyone, "Prometheus metrics (text format 0.0.4): bench telemetry and HTTP counts.",
              [bench, metrics](const Request&) {
                Response r;
                r.content_type = "text/plain; version=0.0.4";
                r.body = prometheus_text(bench->snapshot()->status, metrics->by_status(), metrics->ws(), metrics->connections());
                return r;
              }});
  router.add(answering({"GET", "/api/bench/status", Role::viewer,
                        "Telemetry of both drives, setpoints, the safety supervisor's phase and trip, recent events.",
                        [bench](const Request&) { return status_response(*bench->snapshot()); }},
                       status_schema()));
  router.add(answering({"GET", "/api/bench/config", Role::viewer, "Limits the bench's setpoints are validated against.",
                        [max_speed_rpm, max_load_Nm](const Request&) {
                          return json_response(200, {{"speed_rpm", {{"min", 0}, {"max", max_speed_rpm}}},
                                                     {"load_Nm", {{"min", 0}, {"max", max_load_Nm}}},
                                                     {"angle_deg", {{"min_exclusive", bench::kMotoringAngleAbove_deg}, {"max_exclusive", bench::kMotoringAngleBelow_deg}}},
                                                     {"tick_ms", BenchRuntime::kTick.count()}});
                        }},
                       bench_config_schema()));
  Route lock_routes[] = {
      {"GET", "/api/bench/lock", Role::viewer, "Who holds the operators' control lock.",
       [control](const Request&) { return json_response(200, control->describe()); }},
      {"POST", "/api/bench/lock", Role::operator_,
       "Claim the control lock (operator commands claim it too); 409 while another operator holds it.",
       [control](const Request& req) {
         if (!control->claim(req.caller_id)) return locked(*control);
         return json_response(200, control->describe());
       }},
      {"DELETE", "/api/bench/lock", Role::operator_, "Release the control lock; 409 when another operator holds it.",
       [control](const Request& req) {
         if (!control->release(req.caller_id)) return locked(*control);
         return json_response(200, control->describe());
       }}};
  for (Route& r : lock_routes) router.add(answering(std::move(r), lock_schema()));
  // Every signed-in role may stop the bench (a viewer watching it run away must not have to find
  // an operator); who pressed it, token id and role, goes into the trip, its event and the log.
  router.add({"POST", "/api/bench/estop", Role::viewer,
              "E-stop (any signed-in role): ahead of every queued command, heartbeats stopped, both drives disabled at "
              "once (one request each), then read back and the disable repeated until both read stopped (a lost one every "
              "tick, an acknowledged one at most every 0.1 s; a drive ramping down within its documented stop time is "
              "left to it); the held speed and load setpoints are zeroed; latched until reset. Answers once both disables were "
              "tried, with the status: supervisor.disable says per drive whether it was acknowledged, is being "
              "repeated (and why), is stopping within its stop time or is confirmed; the trip's detail names who pressed it.",
              AsyncHandler([bench](const Request& req, Reply reply) {
                bench->estop("E-stop by " + (req.caller_id.empty() ? std::string("an unnamed token") : req.caller_id) + " (" +
                                 role_name(req.caller) + ")",
                             answer(std::move(reply)));
              })});
  router.add({"POST", "/api/bench/reset", Role::operator_,
              "Clear the supervisor's latched trip and the drives' faults, resume the heartbeats (refused during an "
              "ordered stop or while a drive still reads back running).",
              AsyncHandler([bench, control](const Request& req, Reply reply) {
                if (!control->claim(req.caller_id)) return reply(locked(*control));
                bench->reset(answer(std::move(reply)));
              })});
  // The router checks the bodies against these schemas (json_schema.hpp) before the handlers
  // run: what remains here is the bench's own business.
  router.add({"POST", "/api/bench/enable", Role::operator_,
              "Enable both drives with the current setpoints, or disable them by the ordered stop.",
              AsyncHandler([bench, control](const Request& req, Reply reply) {
                if (!control->claim(req.caller_id)) return reply(locked(*control));
                bench->enable(req.json["enabled"].get<bool>(), answer(std::move(reply)));
              }),
              synbench::Json{{"type", "object"},
                             {"required", synbench::Json::array({"enabled"})},
                             {"additionalProperties", false},
                             {"properties", {{"enabled", {{"type", "boolean"}}}}}}});
  router.add({"POST", "/api/bench/mode", Role::operator_,
              "Choose the estimator and/or PWM scheme manual operation runs with (drives disabled).",
              AsyncHandler([bench, control](const Request& req, Reply reply) {
                if (!control->claim(req.caller_id)) return reply(locked(*control));
                app::DriveModeUpdate mode;
                if (req.json.contains("estimator")) mode.estimator = drivers::parse_estimator(req.json["estimator"].get<std::string>());
                if (req.json.contains("pwm")) mode.pwm = drivers::parse_pwm(req.json["pwm"].get<std::string>());
                bench->set_mode(mode, answer(std::move(reply)));
              }),
              synbench::Json{{"type", "object"},
                             {"additionalProperties", false},
                             {"minProperties", 1},
                             {"properties",
                              {{"estimator", {{"type", "string"}, {"enum", drivers::kEstimatorNames}}},
                               {"pwm", {{"type", "string"}, {"enum", drivers::kPwmNames}}}}}}});
  router.add({"POST", "/api/bench/setpoints", Role::operator_,
              "Set speed_rpm, load_Nm and/or angle_deg (omitted fields keep their value).",
              AsyncHandler([bench, control](const Request& req, Reply reply) {
                if (!control->claim(req.caller_id)) return reply(locked(*control));
                app::SetpointsUpdate sp;
                const auto take = [&req](const char* name, std::optional<double>& out) {
                  if (req.json.contains(name)) out = req.json[name].get<double>();
                };
                take("speed_rpm", sp.speed_rpm);
                take("load_Nm", sp.load_Nm);
                take("angle_deg", sp.angle_deg);
                bench->set_setpoints(sp, answer(std::move(reply)));
              }),
              // The maxima are the bench's, known when the table is built.
              synbench::Json{{"type", "object"},
                             {"additionalProperties", false},
                             {"minProperties", 1},
                             {"properties",
                              {{"speed_rpm", number_schema(0, max_speed_rpm, "SynRM speed setpoint")},
                               {"load_Nm", number_schema(0, max_load_Nm, "braking torque of the load")},
                               {"angle_deg", {{"type", "number"}, {"minimum", bench::kMotoringAngleAbove_deg}, {"exclusiveMinimum", true},
                                              {"maximum", bench::kMotoringAngleBelow_deg}, {"exclusiveMaximum", true},
                                              {"description", "current angle, motoring"}}}}}}});
}

}  // namespace synbench::http
