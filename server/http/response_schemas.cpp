// The answers' schemas; see response_schemas.hpp.
#include "server/http/response_schemas.hpp"

#include "drivers/modes.hpp"

namespace synbench::http {

synbench::Json closed_object(synbench::Json properties, bool nullable, std::initializer_list<const char*> optional) {
  synbench::Json required = synbench::Json::array();
  for (const auto& [name, _] : properties.items()) {
    bool skip = false;
    for (const char* o : optional) skip = skip || name == o;
    if (!skip) required.push_back(name);
  }
  synbench::Json o = {{"type", "object"}, {"required", std::move(required)}, {"properties", std::move(properties)},
                      {"additionalProperties", false}};
  if (nullable) o["nullable"] = true;
  return o;
}

Route answering(Route route, synbench::Json schema) {
  route.response_schema = std::move(schema);
  return route;
}

namespace {

const synbench::Json kNum = {{"type", "number"}}, kInt = {{"type", "integer"}}, kBool = {{"type", "boolean"}},
                     kStr = {{"type", "string"}};

synbench::Json nullable(synbench::Json s) {
  s["nullable"] = true;
  return s;
}

// disable_json()'s object: null until a stop's disable was sent.
synbench::Json disable_schema() {
  const synbench::Json drive = closed_object(
      {{"state", {{"type", "string"}, {"enum", {"acknowledged", "repeating", "confirmed", "stopping"}}}},
       {"first_acknowledged", kBool},
       {"attempts", kInt},
       {"error", nullable(kStr)},
       {"confirmed_s", nullable(kNum)},
       {"setpoint_zeroed", kBool}});
  return closed_object({{"at_s", kNum}, {"confirmed", kBool}, {"synrm", drive}, {"load", drive}}, true);
}

}  // namespace

synbench::Json status_schema() {
  const synbench::Json code_raw = {{"type", "integer"}, {"nullable", true},
                                   {"description", "the device's own code of a fault its profile has no label for "
                                                   "(fault unknown), else null"}};
  return closed_object(
      {{"t_s", kNum},
       {"enabled", kBool},
       {"stopping", kBool},
       {"heartbeats", kBool},
       {"setpoints", closed_object({{"speed_rpm", kNum}, {"load_Nm", kNum}, {"angle_deg", kNum}})},
       {"commanded", closed_object({{"speed_rpm", kNum}, {"load_Nm", kNum}, {"angle_deg", kNum}})},
       {"mode", closed_object({{"estimator", kStr}, {"pwm", kStr}})},
       {"synrm", closed_object({{"speed_rpm", kNum}, {"im_A", kNum}, {"id_A", kNum}, {"iq_A", kNum}, {"ud_V", kNum},
                                {"uq_V", kNum}, {"udc_V", kNum}, {"pac_W", kNum}, {"temp_C", nullable(kNum)},
                                {"voltage_limited", kBool}, {"lock_lost", kBool}, {"pos_err_deg", nullable(kNum)},
                                {"state", kStr}, {"fault", kStr}, {"fault_code_raw", code_raw}},
                               true)},
       {"load", closed_object({{"torque_Nm", kNum}, {"iq_A", kNum}, {"state", kStr}, {"fault", kStr},
                               {"fault_code_raw", code_raw}},
                              true)},
       {"synrm_error", nullable(kStr)},
       {"load_error", nullable(kStr)},
       {"supervisor",
        closed_object({{"phase", {{"type", "string"},
                                  {"enum", {"normal", "stopping_load", "stopping_speed", "stopped", "estopped"}}}},
                       {"tripped", kBool},
                       {"trip", closed_object({{"fault", kStr}, {"fault_code_raw", code_raw}, {"detail", kStr}, {"at_s", kNum}})},
                       {"alarm", closed_object({{"detail", kStr}, {"at_s", kNum}}, true)},
                       {"disable", disable_schema()}},
                      false, {"trip"})},
       {"loop", closed_object({{"ticks", kInt}, {"overruns", kInt}})},
       {"sweep", closed_object({{"id", kInt}, {"state", kStr}, {"done", kInt}, {"total", kInt}, {"error", kStr},
                                {"current_index", nullable(kInt)},
                                {"point", closed_object({{"speed_rpm", kNum}, {"load_Nm", kNum}, {"angle_deg", kNum},
                                                         {"estimator", kStr}, {"pwm", kStr}},
                                                        true)}},
                               true)},
       {"events", {{"type", "array"}, {"items", closed_object({{"t_s", kNum}, {"kind", kStr}, {"message", kStr}})}}}});
}

synbench::Json health_schema() {
  return closed_object(
      {{"status", {{"type", "string"}, {"enum", synbench::Json::array({"ok"})}}}, {"version", kStr}, {"instance", kStr}, {"bench_time_s", kNum}, {"ticks", kInt}});
}

synbench::Json bench_config_schema() {
  const synbench::Json range = closed_object({{"min", kNum}, {"max", kNum}});
  return closed_object({{"speed_rpm", range},
                        {"load_Nm", range},
                        {"angle_deg", closed_object({{"min_exclusive", kNum}, {"max_exclusive", kNum}})},
                        {"tick_ms", kInt}});
}

synbench::Json lock_schema() {
  return closed_object({{"holder", nullable(kStr)}, {"idle_s", kNum}, {"expires_in_s", kNum}}, false,
                       {"idle_s", "expires_in_s"});
}

synbench::Json whoami_schema() {
  return closed_object({{"role", {{"type", "string"}, {"enum", {"anyone", "viewer", "operator"}}}}, {"id", kStr}});
}

synbench::Json sweep_schema(bool with_plan) {
  synbench::Json p = {
      {"id", kInt},
      {"name", kStr},
      {"state", {{"type", "string"}, {"enum", {"created", "running", "paused", "completed", "aborted", "faulted"}}}},
      {"total_points", kInt},
      {"points_stored", kInt},
      {"created_at", kStr},
      {"started_at", nullable(kStr)},
      {"finished_at", nullable(kStr)},
      {"last_error", nullable(kStr)},
      {"software_version", kStr},
      {"bench", closed_object({{"name", kStr},
                               {"host", kStr},
                               {"devices", {{"type", "array"},
                                            {"items", closed_object({{"device", kStr}, {"profile", kStr}, {"version", kStr}})}}}})},
      {"key", nullable(kStr)}};
  if (with_plan) p["plan"] = {{"type", "object"}, {"description", "the sweep plan as run (docs/sweep-plan.md)"}};
  return closed_object(std::move(p));
}

synbench::Json points_schema() {
  return {{"type", "array"},
          {"items",
           {{"type", "object"},
            {"required", synbench::Json::array({"point_index"})},
            {"properties", {{"point_index", {{"type", "integer"}, {"minimum", 0}}}}},
            {"description", "point_index and the point record's members (docs/record.md)"}}}};
}

namespace {
// The efficiency map interpolated, with iso-lines (bench/efficiency_contours.hpp).
synbench::Json contours_schema() {
  const synbench::Json point = {{"type", "array"}, {"items", kNum}, {"minItems", 2}, {"maxItems", 2}};
  const synbench::Json entry = {
      {"type", "object"},
      {"required", synbench::Json::array({"estimator", "pwm", "speed_rpm", "load_Nm", "efficiency", "levels", "lines"})},
      {"properties",
       {{"estimator", kStr},
        {"pwm", kStr},
        {"speed_rpm", {{"type", "array"}, {"items", kNum}}},
        {"load_Nm", {{"type", "array"}, {"items", kNum}}},
        {"efficiency", {{"type", "array"}, {"items", {{"type", "array"}, {"items", nullable(kNum)}}}}},
        {"levels", {{"type", "array"}, {"items", kNum}}},
        {"lines",
         {{"type", "array"},
          {"items", closed_object({{"level", kNum},
                                   {"segments", {{"type", "array"}, {"items", {{"type", "array"}, {"items", point}}}}}})}}}}}};
  return {{"type", "object"},
          {"required", synbench::Json::array({"entries"})},
          {"properties", {{"entries", {{"type", "array"}, {"items", entry}}}}}};
}
}  // namespace

namespace {
// An open object (other members allowed) requiring `properties`.
synbench::Json open_object(synbench::Json properties) {
  synbench::Json required = synbench::Json::array();
  for (const auto& [name, _] : properties.items()) required.push_back(name);
  return {{"type", "object"}, {"required", std::move(required)}, {"properties", std::move(properties)}};
}

synbench::Json entries_of(synbench::Json entry) {
  return open_object({{"entries", {{"type", "array"}, {"items", std::move(entry)}}}});
}

// The uncertainties the analysis adds (docs/analysis.md, "Uncertainty"): null where unknown.
synbench::Json curves_schema() {
  const synbench::Json optimum = open_object({{"im_u_A", nullable(kNum)},
                                              {"im_u_repeat_A", nullable(kNum)},
                                              {"pdcm_u_W", nullable(kNum)},
                                              {"pdcm_u_repeat_W", nullable(kNum)},
                                              {"pm_u_W", nullable(kNum)},
                                              {"efficiency_u", nullable(kNum)},
                                              {"efficiency_u_repeat", nullable(kNum)}});
  return entries_of(open_object({{"mtpa", optimum},
                                 {"me", optimum},
                                 {"mtpa_angle_u_deg", nullable(kNum)},
                                 {"me_angle_u_deg", nullable(kNum)},
                                 {"me_minus_mtpa_deg", nullable(kNum)},
                                 {"me_minus_mtpa_u_deg", nullable(kNum)},
                                 {"me_minus_mtpa_significant", nullable(kBool)}}));
}

synbench::Json deltas_schema() {
  const synbench::Json trajectory = open_object({{"delta_angle_u_deg", nullable(kNum)},
                                                 {"delta_im_u_A", nullable(kNum)},
                                                 {"delta_pdcm_u_W", nullable(kNum)},
                                                 {"delta_angle_significant", nullable(kBool)},
                                                 {"delta_im_significant", nullable(kBool)},
                                                 {"delta_pdcm_significant", nullable(kBool)}});
  return entries_of(open_object({{"mtpa", trajectory}, {"me", trajectory}}));
}

synbench::Json efficiency_map_schema() {
  const synbench::Json matrix = {{"type", "array"}, {"items", {{"type", "array"}, {"items", nullable(kNum)}}}};
  const synbench::Json cell = open_object({{"pm_u_W", nullable(kNum)},
                                           {"pdcm_u_W", nullable(kNum)},
                                           {"efficiency_u", nullable(kNum)},
                                           {"efficiency_u_repeat", nullable(kNum)}});
  return entries_of(open_object({{"efficiency", matrix},
                                 {"efficiency_u", matrix},
                                 {"efficiency_u_repeat", matrix},
                                 {"cells", {{"type", "array"}, {"items", cell}}}}));
}

// bench::to_json(SweepOutcome): what an adaptive search and a precision target used and reached.
synbench::Json sweep_outcome_schema() {
  const synbench::Json optimum = closed_object({{"angle_deg", kNum},
                                                {"angle_u_deg", nullable(kNum)},
                                                {"refined", kBool},
                                                {"at_edge", kBool},
                                                {"points_in_fit", kInt}});
  const synbench::Json curve = closed_object({{"group", kInt},
                                              {"speed_rpm", kNum},
                                              {"load_Nm", kNum},
                                              {"configuration", kStr},
                                              {"points_used", kInt},
                                              {"finished", kBool},
                                              {"angle_u_target_met", kBool},
                                              {"mtpa", optimum},
                                              {"me", optimum}});
  const synbench::Json adaptive = closed_object({{"curves", {{"type", "array"}, {"items", curve}}},
                                                 {"points_used", kInt},
                                                 {"grid_points", kInt},
                                                 {"grid_step_deg", kNum},
                                                 {"angle_u_target_deg", nullable(kNum)},
                                                 {"curves_target_met", kInt}},
                                                true);
  const synbench::Json precision = closed_object({{"pdcm_u_repeat_target_W", kNum},
                                                  {"points", kInt},
                                                  {"points_missed", kInt},
                                                  {"missed_indices", {{"type", "array"}, {"items", kInt}}}},
                                                 true);
  return closed_object({{"adaptive", adaptive}, {"precision", precision}});
}

synbench::Json uncertainty_schema() {
  const synbench::Json counted = closed_object({{"known", kInt}, {"significant", kInt}});
  const synbench::Json trajectory =
      closed_object({{"delta_angle_deg", counted}, {"delta_im_A", counted}, {"delta_pdcm_W", counted}});
  return open_object(
      {{"description", kStr},
       {"method",
        closed_object({{"propagation", kStr},
                       {"draws", kInt},
                       {"seed", kInt},
                       {"coverage", kNum},
                       {"delta_significance", kStr},
                       {"me_minus_mtpa_significance", kStr}})},
       {"me_minus_mtpa", closed_object({{"curves", kInt}, {"known", kInt}, {"significant", kInt}})},
       {"deltas", closed_object({{"entries", kInt}, {"mtpa", trajectory}, {"me", trajectory}})},
       {"efficiency_map", closed_object({{"cells", kInt}, {"known", kInt}})}});
}
}  // namespace

synbench::Json analysis_schema() {
  return {{"type", "object"},
          {"required", synbench::Json::array({"schema"})},
          {"properties",
           {{"schema", {{"type", "string"}, {"enum", synbench::Json::array({"synbench.analysis/1"})}}},
            {"curves", curves_schema()},
            {"deltas", deltas_schema()},
            {"efficiency_map", efficiency_map_schema()},
            {"efficiency_contours", contours_schema()},
            {"uncertainty", uncertainty_schema()},
            {"sweep_outcome", sweep_outcome_schema()}}},
          {"description", "docs/analysis.md"}};
}

synbench::Json estimate_schema(bool with_plan) {
  synbench::Json p = {{"points", kInt},        {"upper_bound", kBool},          {"groups", kInt},
                      {"speed_changes", kInt}, {"load_changes", kInt},          {"configuration_changes", kInt},
                      {"bench_time_s", kNum},  {"precision_extra_s", kNum}};
  if (with_plan) {
    p["duration_s"] = kNum;
    p["plan"] = {{"type", "object"}, {"description", "the canonical plan (docs/sweep-plan.md)"}};
  }
  return closed_object(std::move(p));
}

synbench::Json presets_schema() {
  return {{"type", "array"},
          {"items", closed_object({{"name", kStr},
                                   {"description", kStr},
                                   {"plan", {{"type", "object"}}},
                                   {"estimate", estimate_schema(false)}})}};
}

synbench::Json estimators_schema() {
  return {{"type", "array"},
          {"items",
           {{"type", "object"},
            {"required", synbench::Json::array({"name", "sensorless", "description", "min_speed_rpm"})},
            {"properties",
             {{"name", {{"type", "string"}, {"enum", drivers::kEstimatorNames}}},
              {"sensorless", kBool},
              {"description", kStr},
              {"min_speed_rpm", {{"type", "number"}, {"minimum", 0}}}}}}}};
}

}  // namespace synbench::http
