// Parsing and validation of bench configs; every problem is reported with its JSON pointer.
#include "drivers/bench_config.hpp"

#include "drivers/json.hpp"

#include <array>
#include <set>
#include <span>
#include <string_view>
#include <vector>
#include <utility>

#include "drivers/json_file.hpp"
#include "drivers/json_reader.hpp"
#include "drivers/profile/number_format.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

constexpr std::array<std::string_view, 3> kTransportNames{"twin", "tcp", "rtu"};  // LinkTransport
constexpr std::array<std::string_view, 3> kParityNames{"none", "even", "odd"};
constexpr std::array<char, 3> kParityCodes{'N', 'E', 'O'};  // libmodbus's, by kParityNames

// A number within [lo, hi]; `whole` also demands a whole number.
std::optional<double> number(const JsonNode& n, double lo, double hi, bool whole = false) {
  return n.number(in_range(lo, hi, whole));
}

std::optional<LinkConfig> link(const JsonNode& j) {
  if (!j.object()) return std::nullopt;
  JsonReader& r = j.reader();
  const std::size_t before = r.count();
  LinkConfig l;
  const auto transport = j["transport"].required().choice<LinkTransport>(kTransportNames, "transport");
  if (transport) l.transport = *transport;
  if (transport == LinkTransport::twin) {
    j.reject_unknown({"transport"});
  } else if (transport == LinkTransport::tcp) {
    j.reject_unknown({"transport", "host", "port", "response_timeout_ms", "byte_timeout_ms", "reconnect_max_ms"});
    if (auto h = j["host"].required().text(true)) l.tcp.host = *h;
    if (auto p = number(j["port"].required(), 1, 65535, true)) l.tcp.port = static_cast<std::uint16_t>(*p);
  } else if (transport == LinkTransport::rtu) {
    j.reject_unknown({"transport", "device", "baud", "parity", "data_bits", "stop_bits", "response_timeout_ms",
                      "byte_timeout_ms", "reconnect_max_ms", "quiet_ms"});
    if (auto d = j["device"].required().text(true)) l.rtu.device = *d;
    if (auto b = number(j["baud"], 300, 4000000, true)) l.rtu.baud = static_cast<int>(*b);
    if (auto p = j["parity"].choice<std::size_t>(kParityNames, "parity")) l.rtu.parity = kParityCodes[*p];
    if (auto d = number(j["data_bits"], 5, 8, true)) l.rtu.data_bits = static_cast<int>(*d);
    if (auto s = number(j["stop_bits"], 1, 2, true)) l.rtu.stop_bits = static_cast<int>(*s);
    if (auto q = number(j["quiet_ms"], 1, 60000)) l.options.rtu_quiet_s = *q / 1000;
  }
  if (auto t = number(j["response_timeout_ms"], 1, 60000)) {
    l.options.response_timeout_s = *t / 1000;
    l.options.rtu_quiet_s = j.has("quiet_ms") ? l.options.rtu_quiet_s : *t / 1000;
  }
  if (auto t = number(j["byte_timeout_ms"], 1, 60000)) l.options.byte_timeout_s = *t / 1000;
  if (auto t = number(j["reconnect_max_ms"], 1, 600000)) l.options.reconnect_max_s = *t / 1000;
  if (r.count() != before) return std::nullopt;
  return l;
}

std::optional<DeviceConfig> device(const JsonNode& j, DeviceKind kind, const std::filesystem::path& base_dir) {
  if (!j.object()) return std::nullopt;
  JsonReader& r = j.reader();
  const std::size_t before = r.count();
  j.reject_unknown({"profile", "link", "unit_id"});
  DeviceConfig d;
  if (auto p = j["profile"].required().text(true)) {
    if (*p == "default") d.profile = default_profile_path(kind);
    else d.profile = std::filesystem::path(*p).is_absolute() ? std::filesystem::path(*p) : base_dir / *p;
  }
  if (auto l = j["link"].required().text(true)) d.link = *l;
  if (auto u = number(j["unit_id"], 1, 247, true)) d.unit_id = static_cast<std::uint8_t>(*u);
  if (r.count() != before) return std::nullopt;
  return d;
}

DeviceConfig& device_of(BenchConfig& c, DeviceKind k) {
  return const_cast<DeviceConfig&>(std::as_const(c).device(k));
}

}  // namespace

const DeviceConfig& BenchConfig::device(DeviceKind k) const {
  switch (k) {
    case DeviceKind::synrm_drive: return synrm_drive;
    case DeviceKind::load_drive: return load_drive;
    case DeviceKind::vfc_meter: return vfc_meter;
  }
  return synrm_drive;
}

bool BenchConfig::on_twin() const {
  const auto it = links.find(synrm_drive.link);
  return it != links.end() && it->second.transport == LinkTransport::twin;
}

BenchConfigResult parse_bench_config(const json& doc, const std::filesystem::path& base_dir) {
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  BenchConfig c;
  if (!root.object()) return {std::nullopt, r.errors};
  root.reject_unknown({"time_scale", "poll_period_ms", "window_margin_s", "retries", "retry_budget_ms", "links",
                       "devices", "limits", "setpoints", "calibration", "uncertainty"});
  if (auto v = number(root["time_scale"], 0.001, 1000)) c.time_scale = *v;
  if (auto v = number(root["poll_period_ms"], 1, 10000)) c.poll_period_ms = *v;
  if (auto v = number(root["window_margin_s"], 0, 3600)) c.window_margin_s = *v;
  if (auto v = number(root["retries"], 0, 10, true)) c.retries = static_cast<int>(*v);
  if (auto v = number(root["retry_budget_ms"], 0, 60000)) c.retry_budget_ms = *v;

  if (const JsonNode l = root["limits"]; l.object()) {
    l.reject_unknown({"max_speed_rpm", "max_current_A", "max_udc_V", "min_udc_V", "max_temp_C", "link_timeout_ms"});
    c.limits.max_speed_rpm = number(l["max_speed_rpm"], 1, 100000);
    c.limits.max_current_A = number(l["max_current_A"], 0.01, 10000);
    c.limits.max_udc_V = number(l["max_udc_V"], 1, 10000);
    c.limits.min_udc_V = number(l["min_udc_V"], 0, 10000);
    c.limits.max_temp_C = number(l["max_temp_C"], -40, 400);
    c.limits.link_timeout_ms = number(l["link_timeout_ms"], 10, 60000);
    if (c.limits.max_udc_V && c.limits.min_udc_V && *c.limits.min_udc_V >= *c.limits.max_udc_V)
      l["min_udc_V"].fail("must be below max_udc_V");
  }
  if (const JsonNode sp = root["setpoints"]; sp.object()) {
    sp.reject_unknown({"max_speed_rpm", "max_load_Nm"});
    c.setpoints.max_speed_rpm = number(sp["max_speed_rpm"], 1, 100000);
    c.setpoints.max_load_Nm = number(sp["max_load_Nm"], 0, 100000);
  }
  if (const JsonNode cal = root["calibration"]; cal.object()) {
    cal.reject_unknown({"load_b1_Nms_per_rad"});
    c.calibration.load_b1_Nms_per_rad = number(cal["load_b1_Nms_per_rad"], 0, 1);
  }
  if (const JsonNode un = root["uncertainty"]; un.object()) {
    // Each a standard uncertainty (k = 1) in the unit its name ends in; docs/uncertainty.md.
    UncertaintyConfig& u = c.uncertainty;
    const std::pair<const char*, double*> keys[] = {
        {"vfc_f0_u_Hz", &u.vfc_f0_u_Hz},
        {"vfc_kf_u_pct", &u.vfc_kf_u_pct},
        {"meter_clock_u_ppm", &u.meter_clock_u_ppm},
        {"dc_sensor_gain_u_pct", &u.dc_sensor_gain_u_pct},
        {"dc_sensor_offset_u_A", &u.dc_sensor_offset_u_A},
        {"power_meter_u_pct", &u.power_meter_u_pct},
        {"udc_gain_u_pct", &u.udc_gain_u_pct},
        {"udc_offset_u_V", &u.udc_offset_u_V},
        {"torque_gain_u_pct", &u.torque_gain_u_pct},
        {"torque_offset_u_Nm", &u.torque_offset_u_Nm},
        {"load_b1_u_Nms_per_rad", &u.load_b1_u_Nms_per_rad},
        {"im_gain_u_pct", &u.im_gain_u_pct},
        {"encoder_counts_per_rev", &u.encoder_counts_per_rev}};
    std::vector<std::string_view> names;
    for (const auto& [k, p] : keys) names.emplace_back(k);
    un.reject_unknown(std::span<const std::string_view>(names));
    for (const auto& [k, p] : keys) {
      const std::string key = k;
      const bool pct = key.ends_with("_pct"), ppm = key.ends_with("_ppm"), counts = key == "encoder_counts_per_rev";
      const double hi = pct ? 100.0 : ppm ? 1.0e5 : counts ? 1.0e9 : key == "vfc_f0_u_Hz" ? 1.0e6 : 1.0e3;
      if (auto v = number(un[k], counts ? 1.0 : 0.0, hi)) *p = *v;
    }
  }

  const JsonNode links = root["links"];
  if (links.required().object())
    for (const auto& [key, value] : links.members())
      if (auto l = link(value)) c.links[key] = *l;

  const JsonNode devices = root["devices"];
  if (devices.required().object()) {
    devices.reject_unknown({"synrm_drive", "load_drive", "vfc_meter"});
    std::set<std::string> transports;
    for (const DeviceKind kind : kDeviceKinds) {
      const JsonNode node = devices[name(kind)];
      auto d = device(node.required("required device is missing"), kind, base_dir);
      if (!d) continue;
      const auto link = c.links.find(d->link);
      if (link == c.links.end()) {
        if (links.present() && links.json().is_object() && !links.has(d->link))
          node["link"].fail("'" + d->link + "' is not one of /links");
        continue;
      }
      transports.insert(link->second.transport == LinkTransport::twin ? "twin" : "modbus");
      device_of(c, kind) = *d;
    }
    if (transports.size() > 1)
      devices.fail("the in-process twin cannot be mixed with Modbus links: use twin for all three devices or for none");
  }
  if (!r.ok()) return {std::nullopt, r.errors};
  return {c, {}};
}

BenchConfigResult load_bench_config(const std::filesystem::path& file) {
  JsonParsed read = read_json_file(file);
  if (!read.ok()) return {std::nullopt, {{"", read.error}}};
  return parse_bench_config(read.doc, file.parent_path());
}

void override_unit_id(DeviceProfile& profile, std::uint8_t unit_id) {
  for (ProfileSignal& s : profile.signals)
    if (s.unit_id == profile.unit_id) s.unit_id = unit_id;
  profile.unit_id = unit_id;
}

std::optional<BenchProfiles> load_bench_profiles(const BenchConfig& config, std::vector<ProfileError>& errors) {
  BenchProfiles out;
  bool ok = true;
  for (const DeviceKind kind : kDeviceKinds) {
    const DeviceConfig& d = config.device(kind);
    const std::string path = "/devices/" + std::string(name(kind)) + "/profile";
    // Read here rather than through load_device_profile: a read error already names the file.
    const JsonParsed read = read_json_file(d.profile);
    if (!read.ok()) {
      errors.push_back({path, read.error});
      ok = false;
      continue;
    }
    ProfileParseResult r = parse_device_profile(read.doc);
    if (!r.profile) {
      for (const ProfileError& e : r.errors)
        errors.push_back({path, d.profile.string() + (e.pointer.empty() ? "" : " " + e.pointer) + ": " + e.reason});
      ok = false;
      continue;
    }
    if (r.profile->kind != kind) {
      errors.push_back({path, d.profile.string() + " is a " + std::string(name(r.profile->kind)) +
                                  " profile, not " + std::string(name(kind))});
      ok = false;
      continue;
    }
    if (d.unit_id) override_unit_id(*r.profile, *d.unit_id);
    switch (kind) {
      case DeviceKind::synrm_drive: out.synrm_drive = std::move(*r.profile); break;
      case DeviceKind::load_drive: out.load_drive = std::move(*r.profile); break;
      case DeviceKind::vfc_meter: out.vfc_meter = std::move(*r.profile); break;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

}  // namespace synbench::drivers
