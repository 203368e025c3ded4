// Bench identity: profile versions by content digest, the twin's devices, defaults, JSON form.
#include "db/bench_identity.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>

#include "db/owner.hpp"
#include "drivers/json_file.hpp"
#include "synbench/version.hpp"

namespace synbench::db {
namespace {

// JSON with every object's keys sorted (synbench::Json keeps insertion order): the same
// profile written in another key order has the same digest.
std::string canonical(const synbench::Json& j) {
  if (j.is_object()) {
    std::vector<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
    std::sort(keys.begin(), keys.end());
    std::string out = "{";
    for (const auto& k : keys) out += (out.size() > 1 ? "," : "") + synbench::Json(k).dump() + ":" + canonical(j.at(k));
    return out + "}";
  }
  if (j.is_array()) {
    std::string out = "[";
    for (const auto& e : j) out += (out.size() > 1 ? "," : "") + canonical(e);
    return out + "]";
  }
  return j.dump();
}

}  // namespace

std::string profile_version(const synbench::Json& profile_doc) {
  if (profile_doc.is_object()) {
    const auto v = profile_doc.find("version");
    if (v != profile_doc.end() && v->is_string()) return v->get<std::string>();
  }
  // FNV-1a, 64 bit: a stable digest needing no crypto library; collisions are not a threat
  // model here (it tells versions apart, it does not authenticate them).
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : canonical(profile_doc)) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char out[32];
  std::snprintf(out, sizeof out, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return out;
}

Result<DeviceIdentity> device_identity(std::string device, const std::filesystem::path& profile_file) {
  const drivers::JsonParsed read = drivers::read_json_file(profile_file);
  if (!read.ok()) return make_error(errc::io, read.error);
  DeviceIdentity d;
  d.device = std::move(device);
  const auto n = read.doc.is_object() ? read.doc.find("name") : read.doc.end();
  d.profile = n != read.doc.end() && n->is_string() ? n->get<std::string>() : profile_file.filename().string();
  d.version = profile_version(read.doc);
  return d;
}

std::vector<DeviceIdentity> twin_devices() {
  std::vector<DeviceIdentity> out;
  for (const char* device : {"synrm_drive", "load_drive", "vfc_meter"})
    out.push_back({device, "synbench twin", std::string(kVersion)});
  return out;
}

BenchIdentity resolved(BenchIdentity b) {
  if (b.host.empty()) b.host = detail::this_process().host;
  if (b.name.empty()) b.name = b.host;
  return b;
}

std::string devices_json(const std::vector<DeviceIdentity>& devices) {
  synbench::Json a = synbench::Json::array();
  for (const auto& d : devices) a.push_back({{"device", d.device}, {"profile", d.profile}, {"version", d.version}});
  return a.dump();
}

Result<std::vector<DeviceIdentity>> parse_devices_json(std::string_view text) {
  const auto j = synbench::Json::parse(text, nullptr, /*allow_exceptions=*/false);
  const auto bad = [] { return make_error(errc::bad_record, "devices_json is not an array of {device, profile, version}"); };
  if (j.is_discarded() || !j.is_array()) return bad();
  std::vector<DeviceIdentity> out;
  for (const auto& e : j) {
    if (!e.is_object()) return bad();
    DeviceIdentity d;
    for (auto [key, member] : {std::pair{"device", &DeviceIdentity::device}, std::pair{"profile", &DeviceIdentity::profile},
                               std::pair{"version", &DeviceIdentity::version}}) {
      const auto it = e.find(key);
      if (it == e.end() || !it->is_string()) return bad();
      d.*member = it->get<std::string>();
    }
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace synbench::db
