// Parsing and validation of bench configs; every problem is reported with its JSON pointer.
#include "drivers/bench_config.hpp"

#include "drivers/json.hpp"

#include <cmath>
#include <initializer_list>
#include <set>
#include <utility>

#include "drivers/json_file.hpp"
#include "drivers/profile/number_format.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

bool is_comment(const std::string& key) { return !key.empty() && key.front() == '_'; }

class Parser {
 public:
  std::vector<ProfileError> errors;

  void fail(std::string path, std::string reason) { errors.push_back({std::move(path), std::move(reason)}); }

  bool object(const json& j, const std::string& path) {
    if (j.is_object()) return true;
    fail(path, "must be an object");
    return false;
  }

  void reject_unknown(const json& obj, const std::string& path, std::initializer_list<std::string_view> known) {
    for (const auto& [key, value] : obj.items()) {
      if (is_comment(key)) continue;
      bool ok = false;
      for (auto k : known) ok = ok || k == key;
      if (!ok) fail(path + "/" + json_pointer_token(key), "unknown field");
    }
  }

  // A number within [lo, hi]; `integer` also demands a whole number.
  std::optional<double> number(const json& obj, const std::string& path, const char* key, double lo,
                               double hi, bool integer = false) {
    const auto it = obj.find(key);
    if (it == obj.end()) return std::nullopt;
    const std::string p = path + "/" + key;
    if (!it->is_number() || !std::isfinite(it->get<double>())) {
      fail(p, "must be a number");
      return std::nullopt;
    }
    const double v = it->get<double>();
    if (integer && v != std::floor(v)) {
      fail(p, "must be a whole number");
      return std::nullopt;
    }
    if (v < lo || v > hi) {
      fail(p, format_number(v) + " is outside [" + format_number(lo) + ", " + format_number(hi) + "]");
      return std::nullopt;
    }
    return v;
  }

  std::optional<std::string> text(const json& obj, const std::string& path, const char* key, bool required) {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(path + "/" + key, "required field is missing");
      return std::nullopt;
    }
    if (!it->is_string() || it->get<std::string>().empty()) {
      fail(path + "/" + key, "must be a non-empty string");
      return std::nullopt;
    }
    return it->get<std::string>();
  }

  std::optional<LinkConfig> link(const json& j, const std::string& path);
  std::optional<DeviceConfig> device(const json& j, const std::string& path, DeviceKind kind,
                                     const std::filesystem::path& base_dir);
};

std::optional<LinkConfig> Parser::link(const json& j, const std::string& path) {
  if (!object(j, path)) return std::nullopt;
  const std::size_t before = errors.size();
  LinkConfig l;
  const auto transport = text(j, path, "transport", true);
  if (transport == "twin") {
    l.transport = LinkTransport::twin;
    reject_unknown(j, path, {"transport"});
  } else if (transport == "tcp") {
    l.transport = LinkTransport::tcp;
    reject_unknown(j, path, {"transport", "host", "port", "response_timeout_ms", "byte_timeout_ms",
                             "reconnect_max_ms"});
    if (auto h = text(j, path, "host", true)) l.tcp.host = *h;
    if (!j.contains("port")) fail(path + "/port", "required field is missing");
    if (auto p = number(j, path, "port", 1, 65535, true)) l.tcp.port = static_cast<std::uint16_t>(*p);
  } else if (transport == "rtu") {
    l.transport = LinkTransport::rtu;
    reject_unknown(j, path, {"transport", "device", "baud", "parity", "data_bits", "stop_bits",
                             "response_timeout_ms", "byte_timeout_ms", "reconnect_max_ms", "quiet_ms"});
    if (auto d = text(j, path, "device", true)) l.rtu.device = *d;
    if (auto b = number(j, path, "baud", 300, 4000000, true)) l.rtu.baud = static_cast<int>(*b);
    if (auto p = text(j, path, "parity", false)) {
      if (*p == "none") l.rtu.parity = 'N';
      else if (*p == "even") l.rtu.parity = 'E';
      else if (*p == "odd") l.rtu.parity = 'O';
      else fail(path + "/parity", "'" + *p + "' is not a parity (none, even, odd)");
    }
    if (auto d = number(j, path, "data_bits", 5, 8, true)) l.rtu.data_bits = static_cast<int>(*d);
    if (auto s = number(j, path, "stop_bits", 1, 2, true)) l.rtu.stop_bits = static_cast<int>(*s);
    if (auto q = number(j, path, "quiet_ms", 1, 60000)) l.options.rtu_quiet_s = *q / 1000;
  } else if (transport) {
    fail(path + "/transport", "'" + *transport + "' is not a transport (twin, tcp, rtu)");
  }
  if (auto t = number(j, path, "response_timeout_ms", 1, 60000)) {
    l.options.response_timeout_s = *t / 1000;
    l.options.rtu_quiet_s = j.contains("quiet_ms") ? l.options.rtu_quiet_s : *t / 1000;
  }
  if (auto t = number(j, path, "byte_timeout_ms", 1, 60000)) l.options.byte_timeout_s = *t / 1000;
  if (auto t = number(j, path, "reconnect_max_ms", 1, 600000)) l.options.reconnect_max_s = *t / 1000;
  if (errors.size() != before) return std::nullopt;
  return l;
}

std::optional<DeviceConfig> Parser::device(const json& j, const std::string& path, DeviceKind kind,
                                           const std::filesystem::path& base_dir) {
  if (!object(j, path)) return std::nullopt;
  const std::size_t before = errors.size();
  reject_unknown(j, path, {"profile", "link", "unit_id"});
  DeviceConfig d;
  if (auto p = text(j, path, "profile", true)) {
    if (*p == "default") d.profile = default_profile_path(kind);
    else d.profile = std::filesystem::path(*p).is_absolute() ? std::filesystem::path(*p) : base_dir / *p;
  }
  if (auto l = text(j, path, "link", true)) d.link = *l;
  if (auto u = number(j, path, "unit_id", 1, 247, true)) d.unit_id = static_cast<std::uint8_t>(*u);
  if (errors.size() != before) return std::nullopt;
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
  Parser p;
  BenchConfig c;
  if (!p.object(doc, "")) return {std::nullopt, p.errors};
  p.reject_unknown(doc, "", {"time_scale", "poll_period_ms", "window_margin_s", "retries", "retry_budget_ms", "links",
                             "devices", "limits", "setpoints", "calibration"});
  if (auto v = p.number(doc, "", "time_scale", 0.001, 1000)) c.time_scale = *v;
  if (auto v = p.number(doc, "", "poll_period_ms", 1, 10000)) c.poll_period_ms = *v;
  if (auto v = p.number(doc, "", "window_margin_s", 0, 3600)) c.window_margin_s = *v;
  if (auto v = p.number(doc, "", "retries", 0, 10, true)) c.retries = static_cast<int>(*v);
  if (auto v = p.number(doc, "", "retry_budget_ms", 0, 60000, false)) c.retry_budget_ms = *v;

  if (const auto l = doc.find("limits"); l != doc.end() && p.object(*l, "/limits")) {
    p.reject_unknown(*l, "/limits", {"max_speed_rpm", "max_current_A", "max_udc_V", "min_udc_V", "max_temp_C",
                                     "link_timeout_ms"});
    c.limits.max_speed_rpm = p.number(*l, "/limits", "max_speed_rpm", 1, 100000);
    c.limits.max_current_A = p.number(*l, "/limits", "max_current_A", 0.01, 10000);
    c.limits.max_udc_V = p.number(*l, "/limits", "max_udc_V", 1, 10000);
    c.limits.min_udc_V = p.number(*l, "/limits", "min_udc_V", 0, 10000);
    c.limits.max_temp_C = p.number(*l, "/limits", "max_temp_C", -40, 400);
    c.limits.link_timeout_ms = p.number(*l, "/limits", "link_timeout_ms", 10, 60000);
    if (c.limits.max_udc_V && c.limits.min_udc_V && *c.limits.min_udc_V >= *c.limits.max_udc_V)
      p.fail("/limits/min_udc_V", "must be below max_udc_V");
  }
  if (const auto sp = doc.find("setpoints"); sp != doc.end() && p.object(*sp, "/setpoints")) {
    p.reject_unknown(*sp, "/setpoints", {"max_speed_rpm", "max_load_Nm"});
    c.setpoints.max_speed_rpm = p.number(*sp, "/setpoints", "max_speed_rpm", 1, 100000);
    c.setpoints.max_load_Nm = p.number(*sp, "/setpoints", "max_load_Nm", 0, 100000);
  }
  if (const auto cal = doc.find("calibration"); cal != doc.end() && p.object(*cal, "/calibration")) {
    p.reject_unknown(*cal, "/calibration", {"load_b1_Nms_per_rad"});
    c.calibration.load_b1_Nms_per_rad = p.number(*cal, "/calibration", "load_b1_Nms_per_rad", 0, 1);
  }

  const auto links = doc.find("links");
  if (links == doc.end()) {
    p.fail("/links", "required field is missing");
  } else if (p.object(*links, "/links")) {
    for (const auto& [key, value] : links->items()) {
      if (is_comment(key)) continue;
      if (auto l = p.link(value, "/links/" + json_pointer_token(key))) c.links[key] = *l;
    }
  }

  const auto devices = doc.find("devices");
  if (devices == doc.end()) {
    p.fail("/devices", "required field is missing");
  } else if (p.object(*devices, "/devices")) {
    p.reject_unknown(*devices, "/devices", {"synrm_drive", "load_drive", "vfc_meter"});
    std::set<std::string> transports;
    for (const DeviceKind kind : kDeviceKinds) {
      const std::string key(name(kind));
      const std::string path = "/devices/" + key;
      const auto it = devices->find(key);
      if (it == devices->end()) {
        p.fail(path, "required device is missing");
        continue;
      }
      auto d = p.device(*it, path, kind, base_dir);
      if (!d) continue;
      const auto link = c.links.find(d->link);
      if (link == c.links.end()) {
        if (links != doc.end() && links->is_object() && !links->contains(d->link))
          p.fail(path + "/link", "'" + d->link + "' is not one of /links");
        continue;
      }
      transports.insert(link->second.transport == LinkTransport::twin ? "twin" : "modbus");
      device_of(c, kind) = *d;
    }
    if (transports.size() > 1)
      p.fail("/devices", "the in-process twin cannot be mixed with Modbus links: use twin for all "
                         "three devices or for none");
  }
  if (!p.errors.empty()) return {std::nullopt, p.errors};
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
        errors.push_back({path, d.profile.string() + (e.path.empty() ? "" : " " + e.path) + ": " + e.reason});
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
