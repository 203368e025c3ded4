// The telemetry history route; see telemetry_routes.hpp and docs/api.md.
#include "server/http/telemetry_routes.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "server/http/response_schemas.hpp"

namespace synbench::http {

namespace {

constexpr double kMaxSpan_s = 3600;
constexpr std::size_t kMaxPoints = 20000;

// The channels of a sample, named as the telemetry message names them.
struct Channel {
  const char* name;
  float app::TelemetrySample::*field;
};
constexpr Channel kChannels[] = {
    {"speed_rpm", &app::TelemetrySample::speed_rpm},   {"torque_Nm", &app::TelemetrySample::torque_Nm},
    {"im_A", &app::TelemetrySample::im_A},             {"id_A", &app::TelemetrySample::id_A},
    {"iq_A", &app::TelemetrySample::iq_A},             {"udc_V", &app::TelemetrySample::udc_V},
    {"pac_W", &app::TelemetrySample::pac_W},           {"temp_C", &app::TelemetrySample::temp_C},
    {"pos_err_deg", &app::TelemetrySample::pos_err_deg}, {"cmd_speed_rpm", &app::TelemetrySample::cmd_speed_rpm},
    {"cmd_load_Nm", &app::TelemetrySample::cmd_load_Nm}, {"cmd_angle_deg", &app::TelemetrySample::cmd_angle_deg},
    {"enabled", &app::TelemetrySample::enabled}};

// A float as the shortest decimal that reads back as that float (7 significant digits at most),
// not the 17 of its double: the answer stays small.
synbench::Json compact(float v) {
  if (!std::isfinite(v)) return nullptr;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.7g", static_cast<double>(v));
  return std::strtod(buf, nullptr);
}

// ?name= as a number in [lo, hi], or `fallback` when absent; a 400 naming it otherwise.
std::optional<double> number_param(const Request& req, const char* name, double lo, double hi, double fallback,
                                   Response& error) {
  const auto it = req.query.find(name);
  if (it == req.query.end()) return fallback;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || end != it->second.c_str() + it->second.size() || errno == ERANGE || !std::isfinite(v) ||
      v < lo || v > hi) {
    char range[64];
    std::snprintf(range, sizeof range, "[%g, %g]", lo, hi);
    error = error_response(400, "bad_field", std::string(name) + ": '" + it->second + "' is not a number in " + range);
    return std::nullopt;
  }
  return v;
}

synbench::Json history_schema() {
  const synbench::Json column = {{"type", "array"}, {"items", {{"type", "number"}, {"nullable", true}}}};
  synbench::Json channels;
  for (const auto& c : kChannels) channels[c.name] = column;
  return closed_object({{"period_s", {{"type", "number"}}},
                        {"capacity", {{"type", "integer"}}},
                        {"t_s", {{"type", "array"}, {"items", {{"type", "number"}}}}},
                        {"channels", closed_object(channels)}});
}

}  // namespace

synbench::Json history_json(const app::TelemetryHistory& history, double span_s, std::size_t max_points) {
  const auto samples = history.recent(span_s, max_points);
  synbench::Json t = synbench::Json::array();
  for (const auto& s : samples) t.push_back(std::round(s.t_s * 1000) / 1000);
  synbench::Json channels = synbench::Json::object();
  for (const auto& c : kChannels) {
    synbench::Json col = synbench::Json::array();
    for (const auto& s : samples) col.push_back(compact(s.*c.field));
    channels[c.name] = std::move(col);
  }
  return {{"period_s", history.period_s()},
          {"capacity", history.capacity()},
          {"t_s", std::move(t)},
          {"channels", std::move(channels)}};
}

void add_telemetry_routes(Router& router, const app::TelemetryHistory& history, Worker& worker) {
  const app::TelemetryHistory* h = &history;
  router.add(answering(
      {"GET", "/api/telemetry/history", Role::viewer,
       "The daemon's telemetry ring (20 Hz, the last 15 min, kept across restarts) as columns: ?span_s= (default 900, "
       "at most 3600) of bench time before the newest sample, ?max_points= (default 20000) decimating evenly.",
       worker.offload([h](const Request& req) {
         Response err;
         const auto span = number_param(req, "span_s", 0, kMaxSpan_s, 900, err);
         if (!span) return err;
         const auto max_points = number_param(req, "max_points", 1, static_cast<double>(kMaxPoints), static_cast<double>(kMaxPoints), err);
         if (!max_points) return err;
         return json_response(200, history_json(*h, *span, static_cast<std::size_t>(*max_points)));
       })},
      history_schema()));
}

}  // namespace synbench::http
