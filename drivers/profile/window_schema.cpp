// The window and meter groups of a profile. A group half mapped is the typical mistake of a
// hand-written profile, so each missing member is reported at its own pointer with the whole
// group named, and a signal of the other meter kind says which kind it belongs to.
#include "drivers/profile/window_schema.hpp"

#include "drivers/json.hpp"

#include <array>
#include <cmath>
#include <span>
#include <string>

namespace synbench::drivers {
namespace {

using json = synbench::Json;
using Names = std::span<const std::string_view>;

constexpr std::array<std::string_view, 3> kMeterNames{"gate", "totalizer", "power"};

// The signals without which the device cannot keep a window (the load drive may lack a start
// coil and length: a trigger line opens its window).
constexpr std::string_view kSynrmWindow[] = {"window_start", "window_length_ms", "window_status", "window_sequence",
                             "window_samples", "window_s"};
constexpr std::string_view kLoadWindow[] = {"window_status", "window_sequence", "window_samples", "window_torque_Nm"};
constexpr std::string_view kGate[] = {"gate_start", "gate_length_ms", "gate_status", "gate_sequence", "counts_m",
                      "counts_g", "gate_s", "idcm_A", "idcg_A"};
constexpr std::string_view kStartAndLength[] = {"window_start", "window_length_ms"};
constexpr std::string_view kTotalizer[] = {"total_m", "total_g", "time_base_ticks"};
constexpr std::string_view kPower[] = {"pdcm_W", "pdcg_W"};

struct Check {
  const json& doc;
  const json& signals;
  std::vector<ProfileError>& errors;

  void fail(std::string path, std::string reason) { errors.push_back({std::move(path), std::move(reason)}); }
  bool maps(std::string_view s) const { return signals.contains(std::string(s)); }
  static std::string list(Names names) {
    std::string out;
    for (const std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
    return out;
  }
  static std::string at(std::string_view s) { return "/signals/" + json_pointer_token(s); }

  // Every member of `names` mapped (true), none (false); a partial group is reported.
  bool group(Names names, const std::string& why) {
    std::size_t mapped = 0;
    for (const std::string_view n : names) mapped += maps(n) ? 1 : 0;
    if (mapped == 0) return false;
    if (mapped < names.size())
      for (const std::string_view n : names)
        if (!maps(n)) fail(at(n), why + ": map all of " + list(names) + ", or none of them");
    return true;
  }
  void require(Names names, const std::string& why) {
    for (const std::string_view n : names)
      if (!maps(n)) fail(at(n), "required " + why);
  }
  void forbid(Names names, const std::string& why) {
    for (const std::string_view n : names)
      if (maps(n)) fail(at(n), why);
  }
  void forbid_key(const char* key, const std::string& why) {
    if (doc.contains(key)) fail(std::string("/") + key, why);
  }

  std::optional<double> positive(const char* key, bool required, bool nonzero_only = false) {
    const auto it = doc.find(key);
    if (it == doc.end()) {
      if (required) fail(std::string("/") + key, "required field is missing");
      return std::nullopt;
    }
    const bool ok = it->is_number() && std::isfinite(it->get<double>()) &&
                    (nonzero_only ? it->get<double>() != 0 : it->get<double>() > 0);
    if (!ok) {
      fail(std::string("/") + key, nonzero_only ? "must be a finite non-zero number" : "must be a positive number");
      return std::nullopt;
    }
    return it->get<double>();
  }

  // poll_period_ms: how often a host-kept window samples the device.
  void poll_period(DeviceProfile& p, bool needed, const std::string& why_not) {
    const auto it = doc.find("poll_period_ms");
    if (!needed) {
      if (it != doc.end()) fail("/poll_period_ms", why_not);
      return;
    }
    if (it == doc.end()) {
      fail("/poll_period_ms", "required: the bench averages this device's telemetry polled at this period");
      return;
    }
    if (!it->is_number_integer() || it->get<std::int64_t>() < 1 || it->get<std::int64_t>() > 60'000) {
      fail("/poll_period_ms", "must be an integer in 1..60000");
      return;
    }
    p.poll_period_ms = static_cast<std::uint32_t>(it->get<std::int64_t>());
  }

  void drive(DeviceProfile& p, Names group) {
    const bool device = this->group(group, "the device keeps its window only with its window signals");
    if (!device) {
      // Results the device accumulates need the device's window to mean anything.
      for (const SignalSpec& s : signal_catalogue(p.kind))
        if (s.role == SignalRole::window_result && maps(s.name))
          fail(at(s.name), "a window result needs the device's window: map all of " + list(group) +
                               ", or no window signal for a window the bench keeps");
      if (maps("window_start") || maps("window_length_ms"))
        forbid(kStartAndLength,
               "a window start needs the device's window: map all of " + list(group) + ", or none of them");
    }
    poll_period(p, !device, "applies only to a profile without window signals (the device keeps this one)");
  }

  void meter(DeviceProfile& p) {
    if (const auto it = doc.find("meter"); it != doc.end()) {
      const auto kind = it->is_string() ? parse_meter_kind(it->get<std::string>()) : std::nullopt;
      if (!kind) {
        fail("/meter", "must be one of gate, totalizer, power");
        return;
      }
      p.meter = *kind;
    }
    const std::string kind = std::string(name(p.meter));
    const auto other = [&](Names names, std::string_view owner) {
      forbid(names, "belongs to meter " + std::string(owner) + ", not " + kind);
    };
    const std::string only_totalizer = "applies to meter totalizer only";
    if (p.meter != MeterKind::totalizer)
      for (const char* key : {"time_base_Hz", "f0_Hz", "kf_Hz_per_A"}) forbid_key(key, only_totalizer);
    switch (p.meter) {
      case MeterKind::gate:
        require(kGate, "for meter gate");
        other(kTotalizer, "totalizer");
        other(kPower, "power");
        break;
      case MeterKind::totalizer:
        require(kTotalizer, "for meter totalizer (free-running counters read at window open and close)");
        other(kGate, "gate");
        other(kPower, "power");
        p.time_base_Hz = positive("time_base_Hz", true).value_or(0);
        p.f0_Hz = positive("f0_Hz", true).value_or(0);
        p.kf_Hz_per_A = positive("kf_Hz_per_A", true, /*nonzero_only=*/true).value_or(0);
        counters();
        break;
      case MeterKind::power:
        require(kPower, "for meter power");
        other(kGate, "gate");
        other(kTotalizer, "totalizer");
        break;
    }
    poll_period(p, p.meter == MeterKind::power,
                "applies to meter power only (a " + kind + " meter times its own window)");
  }

  // A counter wraps at its range only if it is an unsigned integer read without an offset.
  void counters() {
    for (const std::string_view n : kTotalizer) {
      if (!maps(n)) continue;
      const json& s = signals.at(std::string(n));
      if (!s.is_object()) continue;
      if (const auto t = s.find("type"); t != s.end() && t->is_string() && *t != "u16" && *t != "u32")
        fail(at(n) + "/type", "a free-running counter must be u16 or u32 (it wraps at the type's range)");
      if (const auto o = s.find("offset"); o != s.end() && !(o->is_number() && o->get<double>() == 0))
        fail(at(n) + "/offset", "a free-running counter takes no offset");
      if (const auto sc = s.find("scale"); sc != s.end() && !(sc->is_number() && sc->get<double>() == 1))
        fail(at(n) + "/scale", "a free-running counter is read in counts: scale 1");
    }
  }
};

}  // namespace

std::string_view name(MeterKind k) { return kMeterNames[static_cast<std::size_t>(k)]; }

std::optional<MeterKind> parse_meter_kind(std::string_view s) {
  for (std::size_t i = 0; i < kMeterNames.size(); ++i)
    if (kMeterNames[i] == s) return static_cast<MeterKind>(i);
  return std::nullopt;
}

void parse_window_schema(const synbench::Json& doc, DeviceProfile& profile, std::vector<ProfileError>& errors) {
  static const json kNoSignals = json::object();
  const auto it = doc.find("signals");
  Check c{doc, it != doc.end() && it->is_object() ? *it : kNoSignals, errors};
  switch (profile.kind) {
    case DeviceKind::synrm_drive:
    case DeviceKind::load_drive:
      c.forbid_key("meter", "applies to a vfc_meter profile only");
      for (const char* key : {"time_base_Hz", "f0_Hz", "kf_Hz_per_A"})
        c.forbid_key(key, "applies to a vfc_meter profile of meter totalizer only");
      c.drive(profile, profile.kind == DeviceKind::synrm_drive ? Names(kSynrmWindow) : Names(kLoadWindow));
      break;
    case DeviceKind::vfc_meter: c.meter(profile); break;
  }
}

bool host_window(const DeviceProfile& p) { return p.poll_period_ms.has_value(); }

}  // namespace synbench::drivers
