// Parsing and validation of device profiles. Each check names the JSON pointer of the field it
// rejects, so an error message leads a user straight to the line to fix.
#include "drivers/profile/device_profile.hpp"

#include "drivers/json.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <map>
#include <tuple>

#include "drivers/json_file.hpp"
#include "drivers/json_reader.hpp"
#include "drivers/profile/number_format.hpp"
#include "drivers/profile/window_schema.hpp"

#ifndef SYNBENCH_PROFILE_DIR
#error "SYNBENCH_PROFILE_DIR must name drivers/profiles (set by drivers/CMakeLists.txt)"
#endif

namespace synbench::drivers {
namespace {

using json = synbench::Json;

// The choices each enum field shows when it is wrong.
constexpr std::string_view kKindChoices = "synrm_drive, load_drive, vfc_meter";
constexpr std::string_view kOrderChoices = "big, little";

constexpr std::array<std::string_view, 4> kRegisterKindNames{"coil", "discrete_input", "holding", "input"};
constexpr std::array<std::string_view, 3> kAccessNames{"r", "w", "rw"};
constexpr std::array<std::string_view, 3> kWatchdogNames{"counter", "any_write", "none"};
constexpr std::array<std::string_view, 2> kResetModeNames{"level", "pulse"};  // FaultResetMode::Mode
constexpr std::int64_t kMaxMs = 3'600'000;

constexpr int kMinUnitId = 1;
constexpr int kMaxUnitId = 247;  // 0 is broadcast, 248..255 are reserved
constexpr std::int64_t kMaxStopTimeMs = 60000;  // a drive that needs longer is not stopping

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string a_kind(RegisterKind k) {
  switch (k) {
    case RegisterKind::coil: return "a coil";
    case RegisterKind::discrete_input: return "a discrete input";
    case RegisterKind::holding: return "a holding register";
    case RegisterKind::input: return "an input register";
  }
  return "a register";
}

class Parser : public JsonReader {
 public:
  struct Defaults {
    std::uint8_t unit_id;
    WordOrder word_order;
    ByteOrder byte_order;
  };

  std::optional<ProfileSignal> signal(const SignalSpec& spec, const JsonNode& n,
                                      const Defaults& d);

 private:
  void register_encoding(const JsonNode& n, const Defaults& d, ProfileSignal& s);
  void limits(const JsonNode& n, bool scaling_valid, ProfileSignal& s);
  void enum_values(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s);
  void heartbeat(const JsonNode& n, ProfileSignal& s);
  void bit_mask(const JsonNode& n, ProfileSignal& s);
  void array_count(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s);
  void otherwise(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s);
  void reset_mode(const JsonNode& n, ProfileSignal& s);
  // Whether `value` fits the signal's encoding (and its field, for a masked signal).
  static bool encodable(const ProfileSignal& s, double value);
};

std::optional<ProfileSignal> Parser::signal(const SignalSpec& spec, const JsonNode& n, const Defaults& d) {
  if (!n.object("must be an object")) return std::nullopt;
  n.reject_unknown({"unit_id", "register", "address", "type", "word_order", "byte_order", "scale", "offset",
                  "unit", "access", "min", "max", "values", "period_ms", "timeout_ms", "bit", "mask", "otherwise",
                  "reset", "count"});
  const std::size_t errors_before = errors.size();

  ProfileSignal s;
  s.name = spec.name;
  s.role = spec.role;
  s.unit_id = static_cast<std::uint8_t>(
      n["unit_id"].integer(kMinUnitId, kMaxUnitId).value_or(d.unit_id));

  const auto kind = n["register"].required().choice<RegisterKind>(parse_register_kind, "register kind",
                                             "coil, discrete_input, holding, input");
  const auto address = n["address"].required().integer(0, 65535);
  if (!kind) return std::nullopt;  // nothing below can be judged without the table
  s.kind = *kind;

  if (is_bit_kind(s.kind)) {
    s.encoding.type = ValueType::boolean;
    if (!spec.unit.empty())
      n["register"].fail(s.name + " is in " + std::string(spec.unit) + "; " + a_kind(s.kind) +
                                   " carries a single bit, so it needs a holding or input register");
    if (const auto t = n["type"].text(); t && *t != "bool")
      n["type"].fail(a_kind(s.kind) + " carries type bool, not " + in_quotes(*t));
    for (const char* key : {"word_order", "byte_order", "scale", "offset", "min", "max", "values", "bit", "mask",
                            "otherwise"})
      if (n.has(key))
        n[key].fail("does not apply to " + a_kind(s.kind) + " (a single bit)");
  } else {
    register_encoding(n, d, s);
    bit_mask(n, s);
    if (n.has("values")) enum_values(spec, n, s);
    if (n.has("otherwise")) otherwise(spec, n, s);
  }

  array_count(spec, n, s);
  if (address) {
    s.address = static_cast<std::uint16_t>(*address);
    const std::size_t width = address_width(s.encoding.type) * s.values_count();
    if (*address + static_cast<std::int64_t>(width) - 1 > 65535)
      n["address"].fail(std::string(name(s.encoding.type)) + (s.count ? " x " + std::to_string(s.count) : "") +
                        " at " + std::to_string(*address) + " needs " + std::to_string(width) +
                        " registers and runs past 65535");
  }

  const std::string expected_unit(spec.unit);
  s.unit = n["unit"].text().value_or(expected_unit);
  if (s.unit != expected_unit)
    n["unit"].fail("must be " + in_quotes(expected_unit) +
                             ", the unit the bench uses for this signal (scale and offset convert the "
                             "device's unit)");

  const auto access = n["access"].choice<Access>(parse_access, "access", "r, w, rw");
  // Left out, access is what the bench needs: rw for what it writes (reading back a setpoint
  // costs nothing), r for the rest.
  s.access = access.value_or(is_writable_kind(s.kind) && bench_writes(s.role) ? Access::rw : Access::r);
  // The bench writes what it commands and reads the rest; table and access must allow that.
  if (bench_writes(s.role) && !is_writable_kind(s.kind)) {
    // Reported once, at the table: the access field is not the mistake.
    n["register"].fail("the bench writes " + std::string(name(s.role)) +
                                 " signals, so they need a coil or holding register");
  } else if (access) {
    if (*access != Access::r && !is_writable_kind(s.kind))
      n["access"].fail(a_kind(s.kind) + " is read-only");
    else if (bench_writes(s.role) && *access == Access::r)
      n["access"].fail("the bench writes " + std::string(name(s.role)) + " signals; use w or rw");
    else if (!bench_writes(s.role) && *access == Access::w)
      n["access"].fail("the bench reads " + std::string(name(s.role)) + " signals; use r or rw");
  }

  // An unbounded setpoint would let a typo command anything the raw type can carry; a masked
  // field is bounded by its bits.
  if (s.kind == RegisterKind::holding && s.writable() && !n.has("bit") && !n.has("mask")) {
    for (const char* key : {"min", "max"})
      if (!n.has(key)) n[key].fail("required for a register the bench may write");
  }

  if (s.role == SignalRole::heartbeat) {
    heartbeat(n, s);
  } else {
    for (const char* key : {"period_ms", "timeout_ms"})
      if (n.has(key)) n[key].fail("applies to the heartbeat signal only");
  }
  if (s.role == SignalRole::fault_reset)
    reset_mode(n, s);
  else if (n.has("reset"))
    n["reset"].fail("applies to the fault_reset signal only");

  if (errors.size() != errors_before) return std::nullopt;
  return s;
}

void Parser::register_encoding(const JsonNode& n, const Defaults& d, ProfileSignal& s) {
  RegisterEncoding& e = s.encoding;
  const auto type = n["type"].required().choice<ValueType>(parse_value_type, "type", "u16, i16, u32, i32, f32");
  if (type == ValueType::boolean) {
    n["type"].fail("bool is for coils and discrete inputs; a register needs u16, i16, u32, i32 or f32");
    return;
  }
  if (!type) return;
  e.type = *type;

  e.byte_order = n["byte_order"].choice<ByteOrder>(parse_byte_order, "byte order", "big, little")
                     .value_or(d.byte_order);
  e.word_order = d.word_order;
  if (n.has("word_order")) {
    if (address_width(e.type) == 1)
      n["word_order"].fail("applies to 32-bit types only; " + std::string(name(e.type)) + " is one word");
    else
      e.word_order = n["word_order"].choice<WordOrder>(parse_word_order, "word order",
                                           "big, little")
                         .value_or(d.word_order);
  }

  const std::size_t errors_before = errors.size();
  if (const auto scale = n["scale"].number()) {
    if (*scale == 0)
      n["scale"].fail("must not be zero");
    else
      e.scale = *scale;
  }
  if (const auto offset = n["offset"].number()) e.offset = *offset;

  limits(n, errors.size() == errors_before, s);
}

void Parser::limits(const JsonNode& n, bool scaling_valid, ProfileSignal& s) {
  RegisterEncoding& e = s.encoding;
  const auto min = n["min"].number();
  const auto max = n["max"].number();
  if (min && max && *min > *max) {
    n["min"].fail("min " + format_number(*min) + " exceeds max " + format_number(*max));
    return;
  }
  // Each limit must itself be encodable, or part of the declared range could never be sent.
  // Against a scale already reported as wrong that check would only add noise.
  if (!scaling_valid) return;
  RegisterEncoding unbounded = e;
  unbounded.min = -std::numeric_limits<double>::infinity();
  unbounded.max = std::numeric_limits<double>::infinity();
  std::uint16_t words[2];
  bool encodable = true;
  for (const auto& [key, limit] : {std::pair{"min", min}, std::pair{"max", max}}) {
    if (!limit || !encode_registers(unbounded, *limit, words)) continue;
    encodable = false;
    n[key].fail(format_number(*limit) + " is beyond what " + std::string(name(e.type)) +
                               " with scale " + format_number(e.scale) + " and offset " +
                               format_number(e.offset) + " can carry");
  }
  if (!encodable) return;
  if (min) e.min = *min;
  if (max) e.max = *max;
}

void Parser::enum_values(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s) {
  const std::string vpath = n["values"].pointer();
  const json& values = n["values"].json();
  if (spec.labels.empty()) {
    fail(vpath, s.name + " is not an enumerated signal");
    return;
  }
  if (s.encoding.type == ValueType::f32) {
    fail(vpath, "an enumerated signal needs an integer type");
    return;
  }
  if (!values.is_object() || values.empty()) {
    fail(vpath, "must be an object of label: code or label: [codes]");
    return;
  }
  std::map<std::int64_t, std::string> seen;
  for (const auto& [label, v] : values.items()) {
    const std::string vp = vpath + "/" + json_pointer_token(label);
    if (std::find(spec.labels.begin(), spec.labels.end(), label) == spec.labels.end()) {
      std::string known;
      for (const std::string_view l : spec.labels) known += (known.empty() ? "" : ", ") + std::string(l);
      fail(vp, "unknown label for " + s.name + " (expected " + known + ")");
      continue;
    }
    // One code, or several (the first is the one the bench writes).
    std::vector<std::pair<std::string, const json*>> codes;
    if (v.is_array()) {
      if (v.empty()) fail(vp, "must list at least one code");
      for (std::size_t i = 0; i < v.size(); ++i) codes.emplace_back(vp + "/" + std::to_string(i), &v[i]);
    } else {
      codes.emplace_back(vp, &v);
    }
    bool first = true;
    for (const auto& [cp, c] : codes) {
      if (!c->is_number_integer()) {
        fail(cp, "must be an integer or an array of integers");
        continue;
      }
      const auto value = c->get<std::int64_t>();
      if (!encodable(s, static_cast<double>(value))) {
        fail(cp, std::to_string(value) + " is outside the signal's limits, type or bits");
        continue;
      }
      if (const auto [it, inserted] = seen.emplace(value, label); !inserted) {
        fail(cp, std::to_string(value) + " is also a code of " + in_quotes(it->second));
        continue;
      }
      s.values.push_back({value, label, first});
      first = false;
    }
  }
  std::sort(s.values.begin(), s.values.end(), [](const EnumValue& a, const EnumValue& b) { return a.value < b.value; });
}

// An array signal's "count": required on the catalogue's array signals, refused on the others;
// whole registers only (no bits, no mask: each value has its own address).
void Parser::array_count(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s) {
  if (!spec.array) {
    if (n.has("count")) n["count"].fail(s.name + " is a single value; count applies to array signals only");
    return;
  }
  if (!n.has("count")) {
    n["count"].fail("required: " + s.name + " is an array of " + std::to_string(kMinArrayCount) + ".." +
                    std::to_string(kMaxArrayCount) + " consecutive values");
    return;
  }
  const auto count = n["count"].integer(kMinArrayCount, kMaxArrayCount);
  if (!count) return;
  s.count = static_cast<std::uint8_t>(*count);
  if (is_bit_kind(s.kind)) n["register"].fail("an array needs holding or input registers");
  for (const char* key : {"bit", "mask"})
    if (n.has(key)) n[key].fail("does not apply to an array (each value has its own registers)");
}

void Parser::bit_mask(const JsonNode& n, ProfileSignal& s) {
  const bool has_bit = n.has("bit"), has_mask = n.has("mask");
  if (!has_bit && !has_mask) return;
  if (has_bit && has_mask) {
    n["mask"].fail("give bit or mask, not both");
    return;
  }
  const char* key = has_bit ? "bit" : "mask";
  if (s.encoding.type != ValueType::u16) {
    n[key].fail("applies to a u16 register only, not " + std::string(name(s.encoding.type)));
    return;
  }
  const auto v = has_bit ? n["bit"].required().integer(0, 15) : n["mask"].required().integer(1, 65535);
  if (!v) return;
  s.mask = static_cast<std::uint16_t>(has_bit ? (1u << *v) : static_cast<unsigned>(*v));
  // The limits must fit the field, or part of the declared range could never be sent.
  for (const auto& [k, limit] : {std::pair{"min", s.encoding.min}, std::pair{"max", s.encoding.max}})
    if (std::isfinite(limit) && !encodable(s, limit))
      n[k].fail(format_number(limit) + " does not fit the " + std::to_string(std::popcount(s.mask)) +
                               " bit(s) of mask " + std::to_string(s.mask));
}

void Parser::otherwise(const SignalSpec& spec, const JsonNode& n, ProfileSignal& s) {
  if (spec.labels.empty()) {
    n["otherwise"].fail(s.name + " is not an enumerated signal");
    return;
  }
  const auto label = n["otherwise"].text();
  if (!label) return;
  if (std::find(spec.labels.begin(), spec.labels.end(), *label) == spec.labels.end()) {
    std::string known;
    for (const std::string_view l : spec.labels) known += (known.empty() ? "" : ", ") + std::string(l);
    n["otherwise"].fail("unknown label " + in_quotes(*label) + " for " + s.name + " (expected " + known + ")");
    return;
  }
  s.otherwise = *label;
}

void Parser::reset_mode(const JsonNode& n, ProfileSignal& s) {
  const JsonNode r = n["reset"];
  if (!r.object("must be an object: {\"mode\": \"pulse\", \"pulse_ms\": N} or {\"mode\": \"level\"}")) return;
  r.reject_unknown({"mode", "pulse_ms"});
  const auto mode = r["mode"].required().choice<FaultResetMode::Mode>(kResetModeNames, "reset mode");
  if (!mode) return;
  s.reset.mode = *mode;
  if (*mode == FaultResetMode::Mode::level) {
    if (r.has("pulse_ms")) r["pulse_ms"].fail("applies to mode pulse only");
  } else if (const auto ms = r["pulse_ms"].required().integer(1, 60'000)) {
    s.reset.pulse_ms = static_cast<std::uint32_t>(*ms);
  }
}

bool Parser::encodable(const ProfileSignal& s, double value) {
  if (s.masked()) {
    std::uint16_t word = 0;
    return !encode_field(s.encoding, s.mask, value, word);
  }
  std::uint16_t words[2];
  return !encode_registers(s.encoding, value, words);
}

void Parser::heartbeat(const JsonNode& n, ProfileSignal& s) {
  const auto period = n["period_ms"].required().integer(1, kMaxMs);
  const auto timeout = n["timeout_ms"].required().integer(1, kMaxMs);
  if (!period || !timeout) return;
  if (*timeout <= *period) {
    n["timeout_ms"].fail("must exceed period_ms (" + std::to_string(*period) +
                                   "), or every write arrives after the watchdog has tripped");
    return;
  }
  s.heartbeat = HeartbeatTiming{static_cast<std::uint32_t>(*period), static_cast<std::uint32_t>(*timeout)};
}

// Signals in one table of one unit id must not share an address, except masked signals on
// disjoint bits of one register.
void check_overlaps(Parser& p, const std::vector<ProfileSignal>& signals) {
  for (std::size_t i = 0; i < signals.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const ProfileSignal& a = signals[j];
      const ProfileSignal& b = signals[i];
      if (a.kind != b.kind || a.unit_id != b.unit_id) continue;
      if (b.address > a.last_address() || a.address > b.last_address()) continue;
      if (a.masked() && b.masked()) {
        if ((a.mask & b.mask) == 0) continue;
        p.fail("/signals/" + json_pointer_token(b.name) + "/mask",
               "shares bits " + std::to_string(a.mask & b.mask) + " of " + std::string(name(a.kind)) + " " +
                   std::to_string(a.address) + " (unit id " + std::to_string(a.unit_id) + ") with " +
                   in_quotes(a.name) + "; signals may share a register on disjoint bits only");
        continue;
      }
      p.fail("/signals/" + json_pointer_token(b.name) + "/address",
             "overlaps " + in_quotes(a.name) + " (" + std::string(name(a.kind)) + " " + std::to_string(a.address) +
                 ".." + std::to_string(a.last_address()) + ", unit id " + std::to_string(a.unit_id) + ")");
    }
  }
}

// The top-level "watchdog", judged against the signals: a heartbeat signal is a counter watchdog;
// without one a drive must say which watchdog it has, so no drive runs unguarded by omission.
void parse_watchdog(Parser& p, const json& doc, DeviceProfile& profile) {
  // Mapped, even if its mapping has mistakes of its own (reported at the signal).
  const bool heartbeat = doc.at("signals").contains("heartbeat");
  for (const ProfileSignal& s : profile.signals)
    if (s.role == SignalRole::heartbeat && s.heartbeat)
      profile.watchdog = {WatchdogKind::counter, "", s.heartbeat->period_ms, s.heartbeat->timeout_ms};

  const JsonNode w = read_root(doc, p)["watchdog"];
  const bool drive = profile.kind != DeviceKind::vfc_meter;
  if (!w.present()) {
    if (drive && !heartbeat)
      w.fail("required when the profile maps no heartbeat signal: {\"kind\": \"any_write\", ...} or "
             "{\"kind\": \"none\"} (a drive without a watchdog must say so)");
    return;
  }
  if (!w.object("must be an object with kind counter, any_write or none")) return;
  w.reject_unknown({"kind", "refresh", "period_ms", "timeout_ms"});
  const auto kind = w["kind"].required().choice<WatchdogKind>(kWatchdogNames, "watchdog kind");
  if (!kind) return;
  if (*kind != WatchdogKind::any_write)
    for (const char* key : {"refresh", "period_ms", "timeout_ms"})
      if (w.has(key))
        w[key].fail(*kind == WatchdogKind::counter ? "a counter's timing is on the heartbeat signal (period_ms, timeout_ms)"
                                                   : "applies to kind any_write only");
  if (*kind == WatchdogKind::counter) {
    if (!heartbeat) w["kind"].fail("counter needs a heartbeat signal (with period_ms and timeout_ms)");
    return;
  }
  if (heartbeat) {
    w["kind"].fail("the profile maps a heartbeat signal, which is a counter watchdog; " + std::string(name(*kind)) +
                   " contradicts it (remove one)");
    return;
  }
  if (*kind == WatchdogKind::none) {
    profile.watchdog = WatchdogSpec{};
    return;
  }
  const auto refresh = w["refresh"].required().text();
  const auto period = w["period_ms"].required().integer(1, kMaxMs);
  const auto timeout = w["timeout_ms"].required().integer(1, kMaxMs);
  if (refresh) {
    const ProfileSignal* s = profile.find(*refresh);
    const SignalSpec* spec = find_signal_spec(profile.kind, *refresh);
    if (!spec || spec->role != SignalRole::command)
      w["refresh"].fail(in_quotes(*refresh) + " is not a command signal of kind " + std::string(name(profile.kind)));
    else if (!s)
      w["refresh"].fail(in_quotes(*refresh) + " is not mapped by this profile");
  }
  if (period && timeout && *timeout <= *period)
    w["timeout_ms"].fail("must exceed period_ms (" + std::to_string(*period) +
                         "), or every refresh arrives after the watchdog has tripped");
  if (refresh && period && timeout)
    profile.watchdog = {WatchdogKind::any_write, *refresh, static_cast<std::uint32_t>(*period),
                        static_cast<std::uint32_t>(*timeout)};
}

}  // namespace

std::string_view name(WatchdogKind k) { return kWatchdogNames[static_cast<std::size_t>(k)]; }

std::string_view name(RegisterKind k) { return kRegisterKindNames[static_cast<std::size_t>(k)]; }
std::string_view name(Access a) { return kAccessNames[static_cast<std::size_t>(a)]; }

std::optional<RegisterKind> parse_register_kind(std::string_view s) {
  for (std::size_t i = 0; i < kRegisterKindNames.size(); ++i)
    if (kRegisterKindNames[i] == s) return static_cast<RegisterKind>(i);
  return std::nullopt;
}

std::optional<Access> parse_access(std::string_view s) {
  for (std::size_t i = 0; i < kAccessNames.size(); ++i)
    if (kAccessNames[i] == s) return static_cast<Access>(i);
  return std::nullopt;
}

const ProfileSignal* DeviceProfile::find(std::string_view signal) const {
  for (const ProfileSignal& s : signals)
    if (s.name == signal) return &s;
  return nullptr;
}

ProfileParseResult parse_device_profile(const synbench::Json& doc) {
  Parser p;
  const JsonNode root = read_root(doc, p);
  if (!root.object("a profile must be a JSON object")) return {std::nullopt, std::move(p.errors)};
  root.reject_unknown({"name", "description", "kind", "unit_id", "word_order", "byte_order", "signals", "watchdog",
                       "meter", "poll_period_ms", "time_base_Hz", "f0_Hz", "kf_Hz_per_A", "stop_time_ms"});

  DeviceProfile profile;
  profile.name = root["name"].required().text().value_or("");
  profile.description = root["description"].text().value_or("");
  const auto kind = root["kind"].required().choice<DeviceKind>(parse_device_kind, "device kind", kKindChoices);
  const auto unit_id = root["unit_id"].required().integer(kMinUnitId, kMaxUnitId);
  const auto word_order = root["word_order"].choice<WordOrder>(parse_word_order, "word order", kOrderChoices);
  const auto byte_order = root["byte_order"].choice<ByteOrder>(parse_byte_order, "byte order", kOrderChoices);

  const JsonNode signals = root["signals"];
  if (signals.required().object("must be an object of signal name: mapping") && kind) {
    // Without a valid kind the signal names cannot be judged, so signals wait for that fix.
    profile.kind = *kind;
    profile.unit_id = static_cast<std::uint8_t>(unit_id.value_or(kMinUnitId));
    const Parser::Defaults defaults{profile.unit_id, word_order.value_or(WordOrder::big),
                                    byte_order.value_or(ByteOrder::big)};
    for (const auto& [key, value] : signals.members()) {
      const SignalSpec* spec = find_signal_spec(*kind, key);
      if (!spec) {
        value.fail("unknown signal for kind " + std::string(name(*kind)) + " (docs/device-profile.md lists them)");
        continue;
      }
      if (auto s = p.signal(*spec, value, defaults)) profile.signals.push_back(std::move(*s));
    }
    check_overlaps(p, profile.signals);
    parse_watchdog(p, doc, profile);
    if (const JsonNode st = root["stop_time_ms"]; st.present()) {
      if (*kind == DeviceKind::vfc_meter) st.fail("applies to drives only (a meter has nothing to stop)");
      else if (const auto ms = st.integer(0, kMaxStopTimeMs)) profile.stop_time_ms = static_cast<std::uint32_t>(*ms);
    }
    for (const SignalSpec& spec : signal_catalogue(*kind))
      if (spec.required && !signals.has(spec.name))
        signals[spec.name].fail("required signal of kind " + std::string(name(*kind)) + " is missing");
    parse_window_schema(doc, profile, p.errors);
  }

  if (!p.errors.empty()) return {std::nullopt, std::move(p.errors)};
  std::sort(profile.signals.begin(), profile.signals.end(), [](const ProfileSignal& a, const ProfileSignal& b) {
    return std::tie(a.kind, a.unit_id, a.address) < std::tie(b.kind, b.unit_id, b.address);
  });
  return {std::move(profile), {}};
}

ProfileParseResult load_device_profile(const std::filesystem::path& file) {
  JsonParsed read = read_json_file(file);
  if (!read.ok()) return {std::nullopt, {{"", read.error}}};
  return parse_device_profile(read.doc);
}

std::filesystem::path default_profile_dir() {
  // An installed synbench (docker/, a package) finds them where it installed them.
  if (const char* env = std::getenv("SYNBENCH_PROFILE_DIR"); env && *env) return env;
  return SYNBENCH_PROFILE_DIR;
}

std::filesystem::path default_profile_path(DeviceKind kind) {
  return default_profile_dir() / (std::string(name(kind)) + ".json");
}

}  // namespace synbench::drivers
