// The metrics table and its exposition; see metrics_text.hpp.
#include "server/http/metrics_text.hpp"

#include <sstream>
#include <stdexcept>
#include <string_view>

#include "server/http/api_routes.hpp"

namespace synbench::http {

const std::vector<MetricSpec>& metric_specs() {
  static const std::vector<MetricSpec> specs = {
      {"synbench_bench_time_seconds", "gauge", "Bench (twin) time since the daemon started.", "", "always"},
      {"synbench_bench_enabled", "gauge", "1 while the drives are enabled by an operator.", "", "always"},
      {"synbench_supervisor_tripped", "gauge", "1 while the safety supervisor's trip is latched.", "", "always"},
      {"synbench_supervisor_alarm", "gauge", "1 while a drive has not read back stopped after its disable.", "", "always"},
      {"synbench_heartbeats", "gauge", "1 while the drives' watchdog heartbeats are sent (0 after an E-stop).", "", "always"},
      {"synbench_synrm_speed_revolutions_per_minute", "gauge", "SynRM speed.", "", "the SynRM drive was read"},
      {"synbench_synrm_current_amperes", "gauge", "SynRM current magnitude.", "", "the SynRM drive was read"},
      {"synbench_synrm_udc_volts", "gauge", "DC-bus voltage at the SynRM drive.", "", "the SynRM drive was read"},
      {"synbench_synrm_temperature_celsius", "gauge", "SynRM winding temperature.", "",
       "the SynRM drive was read and its profile maps `temp_C` (no sensor, no gauge: a scraped 0 would read as a cold winding)"},
      {"synbench_synrm_pac_watts", "gauge", "SynRM drive output power estimate.", "", "the SynRM drive was read"},
      {"synbench_load_torque_newton_meters", "gauge", "Braking torque of the load machine.", "", "the load drive was read"},
      {"synbench_loop_ticks_total", "counter", "Bench loop ticks.", "", "always"},
      {"synbench_loop_overruns_total", "counter", "Bench loop ticks that started late.", "", "always"},
      {"synbench_http_requests_total", "counter", "HTTP requests answered, by status.", "status", "always"},
      {"synbench_http_connections", "gauge", "HTTP and WebSocket connections open.", "", "always (serve)"},
      {"synbench_http_connections_evicted_total", "counter",
       "Connections closed to make room for a new one (the least trusted, oldest).", "", "always (serve)"},
      {"synbench_ws_clients", "gauge", "WebSocket clients connected.", "", "always (serve)"},
      {"synbench_ws_dropped_total", "counter", "WebSocket clients dropped for not reading (queue bound or write stall).", "",
       "always (serve)"},
  };
  return specs;
}

namespace {

const MetricSpec& spec(std::string_view name) {
  for (const auto& m : metric_specs())
    if (name == m.name) return m;
  throw std::logic_error("no metric " + std::string(name) + " in metric_specs()");
}

}  // namespace

std::string prometheus_text(const app::BenchStatus& s, const std::map<int, std::uint64_t>& http_by_status,
                            const std::optional<WsCounts>& ws, const std::optional<ConnectionCounts>& connections) {
  std::ostringstream o;
  const auto head = [&](std::string_view name) {
    const MetricSpec& m = spec(name);
    o << "# HELP " << m.name << " " << m.help << "\n# TYPE " << m.name << " " << m.type << "\n";
  };
  // Counters as integers: a double would print 1234567 ticks as 1.23457e+06.
  const auto one = [&](std::string_view name, auto v) {
    head(name);
    o << name << " " << v << "\n";
  };
  one("synbench_bench_time_seconds", s.t_s);
  one("synbench_bench_enabled", s.enabled ? 1 : 0);
  one("synbench_supervisor_tripped", s.trip ? 1 : 0);
  one("synbench_supervisor_alarm", s.alarm ? 1 : 0);
  one("synbench_heartbeats", s.heartbeats ? 1 : 0);
  if (s.synrm) {
    one("synbench_synrm_speed_revolutions_per_minute", s.synrm->speed_rpm);
    one("synbench_synrm_current_amperes", s.synrm->im_A);
    one("synbench_synrm_udc_volts", s.synrm->udc_V);
    if (s.synrm->temp_C) one("synbench_synrm_temperature_celsius", *s.synrm->temp_C);
    one("synbench_synrm_pac_watts", s.synrm->pac_W);
  }
  if (s.load) one("synbench_load_torque_newton_meters", s.load->torque_Nm);
  one("synbench_loop_ticks_total", s.ticks);
  one("synbench_loop_overruns_total", s.overruns);
  head("synbench_http_requests_total");
  for (const auto& [code, n] : http_by_status) o << "synbench_http_requests_total{status=\"" << code << "\"} " << n << "\n";
  if (connections) {
    one("synbench_http_connections", connections->open);
    one("synbench_http_connections_evicted_total", connections->evicted);
  }
  if (ws) {
    one("synbench_ws_clients", ws->clients);
    one("synbench_ws_dropped_total", ws->dropped);
  }
  return o.str();
}

std::string metrics_table_markdown() {
  std::string t = "| metric | type | labels | meaning | present |\n|---|---|---|---|---|\n";
  for (const auto& m : metric_specs())
    t += std::string("| `") + m.name + "` | " + m.type + " | " + (*m.labels ? std::string("`") + m.labels + "`" : "") + " | " +
         m.help + " | " + m.when + " |\n";
  return t;
}

}  // namespace synbench::http
