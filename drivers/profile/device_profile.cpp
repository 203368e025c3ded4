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
#include "drivers/profile/number_format.hpp"
#include "drivers/profile/window_schema.hpp"

#ifndef SYNBENCH_PROFILE_DIR
#error "SYNBENCH_PROFILE_DIR must name drivers/profiles (set by drivers/CMakeLists.txt)"
#endif

namespace synbench::drivers {
namespace {

using json = synbench::Json;

constexpr std::array<std::string_view, 4> kRegisterKindNames{"coil", "discrete_input", "holding", "input"};
constexpr std::array<std::string_view, 3> kAccessNames{"r", "w", "rw"};
constexpr std::array<std::string_view, 3> kWatchdogNames{"counter", "any_write", "none"};
constexpr std::int64_t kMaxMs = 3'600'000;

constexpr int kMinUnitId = 1;
constexpr int kMaxUnitId = 247;  // 0 is broadcast, 248..255 are reserved

// JSON keys starting with '_' are comments, as in config/twin.json.
bool is_comment(const std::string& key) { return !key.empty() && key.front() == '_'; }

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

class Parser {
 public:
  std::vector<ProfileError> errors;

  void fail(std::string path, std::string reason) { errors.push_back({std::move(path), std::move(reason)}); }

  // Reports keys outside `known` (comments aside).
  void reject_unknown(const json& obj, const std::string& path, std::initializer_list<std::string_view> known) {
    for (const auto& [key, value] : obj.items()) {
      if (is_comment(key)) continue;
      if (std::find(known.begin(), known.end(), key) == known.end())
        fail(path + "/" + json_pointer_token(key), "unknown field");
    }
  }

  std::optional<std::string> string_field(const json& obj, const std::string& path, const char* key,
                                          bool required) {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(path + "/" + key, "required field is missing");
      return std::nullopt;
    }
    if (!it->is_string()) {
      fail(path + "/" + key, "must be a string");
      return std::nullopt;
    }
    return it->get<std::string>();
  }

  std::optional<double> number_field(const json& obj, const std::string& path, const char* key) {
    const auto it = obj.find(key);
    if (it == obj.end()) return std::nullopt;
    if (!it->is_number() || !std::isfinite(it->get<double>())) {
      fail(path + "/" + key, "must be a finite number");
      return std::nullopt;
    }
    return it->get<double>();
  }

  // An integer within [lo, hi]; reports a missing field only when required.
  std::optional<std::int64_t> integer_field(const json& obj, const std::string& path, const char* key,
                                            std::int64_t lo, std::int64_t hi, bool required) {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(path + "/" + key, "required field is missing");
      return std::nullopt;
    }
    const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
    if (!it->is_number_integer()) {
      fail(path + "/" + key, "must be an integer in " + range);
      return std::nullopt;
    }
    // Unsigned JSON integers above int64 would wrap on get<int64_t>; they are out of range anyway.
    if (it->is_number_unsigned() && it->get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      fail(path + "/" + key, std::to_string(it->get<std::uint64_t>()) + " is outside " + range);
      return std::nullopt;
    }
    const auto v = it->get<std::int64_t>();
    if (v < lo || v > hi) {
      fail(path + "/" + key, std::to_string(v) + " is outside " + range);
      return std::nullopt;
    }
    return v;
  }

  template <typename T, typename ParseFn>
  std::optional<T> enum_field(const json& obj, const std::string& path, const char* key, bool required,
                              ParseFn parse, std::string_view what, std::string_view choices) {
    const auto s = string_field(obj, path, key, required);
    if (!s) return std::nullopt;
    const std::optional<T> v = parse(*s);
    if (!v) fail(path + "/" + key, "unknown " + std::string(what) + " " + in_quotes(*s) + " (expected " +
                                       std::string(choices) + ")");
    return v;
  }

  struct Defaults {
    std::uint8_t unit_id;
    WordOrder word_order;
    ByteOrder byte_order;
  };

  std::optional<ProfileSignal> signal(const SignalSpec& spec, const json& obj, const std::string& path,
                                      const Defaults& d);

 private:
  void register_encoding(const json& obj, const std::string& path, const Defaults& d, ProfileSignal& s);
  void limits(const json& obj, const std::string& path, bool scaling_valid, ProfileSignal& s);
  void enum_values(const SignalSpec& spec, const json& obj, const std::string& path, ProfileSignal& s);
  void heartbeat(const json& obj, const std::string& path, ProfileSignal& s);
  void bit_mask(const json& obj, const std::string& path, ProfileSignal& s);
  void otherwise(const SignalSpec& spec, const json& obj, const std::string& path, ProfileSignal& s);
  void reset_mode(const json& obj, const std::string& path, ProfileSignal& s);
  // Whether `value` fits the signal's encoding (and its field, for a masked signal).
  static bool encodable(const ProfileSignal& s, double value);
};

std::optional<ProfileSignal> Parser::signal(const SignalSpec& spec, const json& obj, const std::string& path,
                                            const Defaults& d) {
  if (!obj.is_object()) {
    fail(path, "must be an object");
    return std::nullopt;
  }
  reject_unknown(obj, path,
                 {"unit_id", "register", "address", "type", "word_order", "byte_order", "scale", "offset",
                  "unit", "access", "min", "max", "values", "period_ms", "timeout_ms", "bit", "mask", "otherwise",
                  "reset"});
  const std::size_t errors_before = errors.size();

  ProfileSignal s;
  s.name = spec.name;
  s.role = spec.role;
  s.unit_id = static_cast<std::uint8_t>(
      integer_field(obj, path, "unit_id", kMinUnitId, kMaxUnitId, false).value_or(d.unit_id));

  const auto kind = enum_field<RegisterKind>(obj, path, "register", true, parse_register_kind, "register kind",
                                             "coil, discrete_input, holding, input");
  const auto address = integer_field(obj, path, "address", 0, 65535, true);
  if (!kind) return std::nullopt;  // nothing below can be judged without the table
  s.kind = *kind;

  if (is_bit_kind(s.kind)) {
    s.encoding.type = ValueType::boolean;
    if (!spec.unit.empty())
      fail(path + "/register", s.name + " is in " + std::string(spec.unit) + "; " + a_kind(s.kind) +
                                   " carries a single bit, so it needs a holding or input register");
    if (const auto t = string_field(obj, path, "type", false); t && *t != "bool")
      fail(path + "/type", a_kind(s.kind) + " carries type bool, not " + in_quotes(*t));
    for (const char* key : {"word_order", "byte_order", "scale", "offset", "min", "max", "values", "bit", "mask",
                            "otherwise"})
      if (obj.contains(key))
        fail(path + "/" + key, "does not apply to " + a_kind(s.kind) + " (a single bit)");
  } else {
    register_encoding(obj, path, d, s);
    bit_mask(obj, path, s);
    if (obj.contains("values")) enum_values(spec, obj, path, s);
    if (obj.contains("otherwise")) otherwise(spec, obj, path, s);
  }

  if (address) {
    s.address = static_cast<std::uint16_t>(*address);
    const std::size_t width = address_width(s.encoding.type);
    if (*address + static_cast<std::int64_t>(width) - 1 > 65535)
      fail(path + "/address", std::string(name(s.encoding.type)) + " at " + std::to_string(*address) +
                                  " needs " + std::to_string(width) + " registers and runs past 65535");
  }

  const std::string expected_unit(spec.unit);
  s.unit = string_field(obj, path, "unit", false).value_or(expected_unit);
  if (s.unit != expected_unit)
    fail(path + "/unit", "must be " + in_quotes(expected_unit) +
                             ", the unit the bench uses for this signal (scale and offset convert the "
                             "device's unit)");

  const auto access = enum_field<Access>(obj, path, "access", false, parse_access, "access", "r, w, rw");
  // Left out, access is what the bench needs: rw for what it writes (reading back a setpoint
  // costs nothing), r for the rest.
  s.access = access.value_or(is_writable_kind(s.kind) && bench_writes(s.role) ? Access::rw : Access::r);
  // The bench writes what it commands and reads the rest; table and access must allow that.
  if (bench_writes(s.role) && !is_writable_kind(s.kind)) {
    // Reported once, at the table: the access field is not the mistake.
    fail(path + "/register", "the bench writes " + std::string(name(s.role)) +
                                 " signals, so they need a coil or holding register");
  } else if (access) {
    if (*access != Access::r && !is_writable_kind(s.kind))
      fail(path + "/access", a_kind(s.kind) + " is read-only");
    else if (bench_writes(s.role) && *access == Access::r)
      fail(path + "/access", "the bench writes " + std::string(name(s.role)) + " signals; use w or rw");
    else if (!bench_writes(s.role) && *access == Access::w)
      fail(path + "/access", "the bench reads " + std::string(name(s.role)) + " signals; use r or rw");
  }

  // An unbounded setpoint would let a typo command anything the raw type can carry; a masked
  // field is bounded by its bits.
  if (s.kind == RegisterKind::holding && s.writable() && !obj.contains("bit") && !obj.contains("mask")) {
    for (const char* key : {"min", "max"})
      if (!obj.contains(key)) fail(path + "/" + key, "required for a register the bench may write");
  }

  if (s.role == SignalRole::heartbeat) {
    heartbeat(obj, path, s);
  } else {
    for (const char* key : {"period_ms", "timeout_ms"})
      if (obj.contains(key)) fail(path + "/" + key, "applies to the heartbeat signal only");
  }
  if (s.role == SignalRole::fault_reset)
    reset_mode(obj, path, s);
  else if (obj.contains("reset"))
    fail(path + "/reset", "applies to the fault_reset signal only");

  if (errors.size() != errors_before) return std::nullopt;
  return s;
}

void Parser::register_encoding(const json& obj, const std::string& path, const Defaults& d, ProfileSignal& s) {
  RegisterEncoding& e = s.encoding;
  const auto type = enum_field<ValueType>(obj, path, "type", true, parse_value_type, "type", "u16, i16, u32, i32, f32");
  if (type == ValueType::boolean) {
    fail(path + "/type", "bool is for coils and discrete inputs; a register needs u16, i16, u32, i32 or f32");
    return;
  }
  if (!type) return;
  e.type = *type;

  e.byte_order = enum_field<ByteOrder>(obj, path, "byte_order", false, parse_byte_order, "byte order", "big, little")
                     .value_or(d.byte_order);
  e.word_order = d.word_order;
  if (obj.contains("word_order")) {
    if (address_width(e.type) == 1)
      fail(path + "/word_order", "applies to 32-bit types only; " + std::string(name(e.type)) + " is one word");
    else
      e.word_order = enum_field<WordOrder>(obj, path, "word_order", false, parse_word_order, "word order",
                                           "big, little")
                         .value_or(d.word_order);
  }

  const std::size_t errors_before = errors.size();
  if (const auto scale = number_field(obj, path, "scale")) {
    if (*scale == 0)
      fail(path + "/scale", "must not be zero");
    else
      e.scale = *scale;
  }
  if (const auto offset = number_field(obj, path, "offset")) e.offset = *offset;

  limits(obj, path, errors.size() == errors_before, s);
}

void Parser::limits(const json& obj, const std::string& path, bool scaling_valid, ProfileSignal& s) {
  RegisterEncoding& e = s.encoding;
  const auto min = number_field(obj, path, "min");
  const auto max = number_field(obj, path, "max");
  if (min && max && *min > *max) {
    fail(path + "/min", "min " + format_number(*min) + " exceeds max " + format_number(*max));
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
    fail(path + "/" + key, format_number(*limit) + " is beyond what " + std::string(name(e.type)) +
                               " with scale " + format_number(e.scale) + " and offset " +
                               format_number(e.offset) + " can carry");
  }
  if (!encodable) return;
  if (min) e.min = *min;
  if (max) e.max = *max;
}

void Parser::enum_values(const SignalSpec& spec, const json& obj, const std::string& path, ProfileSignal& s) {
  const std::string vpath = path + "/values";
  const json& values = obj.at("values");
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

void Parser::bit_mask(const json& obj, const std::string& path, ProfileSignal& s) {
  const bool has_bit = obj.contains("bit"), has_mask = obj.contains("mask");
  if (!has_bit && !has_mask) return;
  if (has_bit && has_mask) {
    fail(path + "/mask", "give bit or mask, not both");
    return;
  }
  const char* key = has_bit ? "bit" : "mask";
  if (s.encoding.type != ValueType::u16) {
    fail(path + "/" + key, "applies to a u16 register only, not " + std::string(name(s.encoding.type)));
    return;
  }
  const auto v = has_bit ? integer_field(obj, path, "bit", 0, 15, true) : integer_field(obj, path, "mask", 1, 65535, true);
  if (!v) return;
  s.mask = static_cast<std::uint16_t>(has_bit ? (1u << *v) : static_cast<unsigned>(*v));
  // The limits must fit the field, or part of the declared range could never be sent.
  for (const auto& [k, limit] : {std::pair{"min", s.encoding.min}, std::pair{"max", s.encoding.max}})
    if (std::isfinite(limit) && !encodable(s, limit))
      fail(path + "/" + k, format_number(limit) + " does not fit the " + std::to_string(std::popcount(s.mask)) +
                               " bit(s) of mask " + std::to_string(s.mask));
}

void Parser::otherwise(const SignalSpec& spec, const json& obj, const std::string& path, ProfileSignal& s) {
  if (spec.labels.empty()) {
    fail(path + "/otherwise", s.name + " is not an enumerated signal");
    return;
  }
  const auto label = string_field(obj, path, "otherwise", false);
  if (!label) return;
  if (std::find(spec.labels.begin(), spec.labels.end(), *label) == spec.labels.end()) {
    std::string known;
    for (const std::string_view l : spec.labels) known += (known.empty() ? "" : ", ") + std::string(l);
    fail(path + "/otherwise", "unknown label " + in_quotes(*label) + " for " + s.name + " (expected " + known + ")");
    return;
  }
  s.otherwise = *label;
}

void Parser::reset_mode(const json& obj, const std::string& path, ProfileSignal& s) {
  const auto it = obj.find("reset");
  if (it == obj.end()) return;
  const std::string rpath = path + "/reset";
  if (!it->is_object()) {
    fail(rpath, "must be an object: {\"mode\": \"pulse\", \"pulse_ms\": N} or {\"mode\": \"level\"}");
    return;
  }
  reject_unknown(*it, rpath, {"mode", "pulse_ms"});
  const auto mode = string_field(*it, rpath, "mode", true);
  if (!mode) return;
  if (*mode == "level") {
    s.reset.mode = FaultResetMode::Mode::level;
    if (it->contains("pulse_ms")) fail(rpath + "/pulse_ms", "applies to mode pulse only");
  } else if (*mode == "pulse") {
    s.reset.mode = FaultResetMode::Mode::pulse;
    if (const auto ms = integer_field(*it, rpath, "pulse_ms", 1, 60'000, true))
      s.reset.pulse_ms = static_cast<std::uint32_t>(*ms);
  } else {
    fail(rpath + "/mode", "unknown reset mode " + in_quotes(*mode) + " (expected pulse, level)");
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

void Parser::heartbeat(const json& obj, const std::string& path, ProfileSignal& s) {
  const auto period = integer_field(obj, path, "period_ms", 1, kMaxMs, true);
  const auto timeout = integer_field(obj, path, "timeout_ms", 1, kMaxMs, true);
  if (!period || !timeout) return;
  if (*timeout <= *period) {
    fail(path + "/timeout_ms", "must exceed period_ms (" + std::to_string(*period) +
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

  const auto it = doc.find("watchdog");
  const bool drive = profile.kind != DeviceKind::vfc_meter;
  if (it == doc.end()) {
    if (drive && !heartbeat)
      p.fail("/watchdog", "required when the profile maps no heartbeat signal: {\"kind\": \"any_write\", ...} or "
                          "{\"kind\": \"none\"} (a drive without a watchdog must say so)");
    return;
  }
  if (!it->is_object()) {
    p.fail("/watchdog", "must be an object with kind counter, any_write or none");
    return;
  }
  p.reject_unknown(*it, "/watchdog", {"kind", "refresh", "period_ms", "timeout_ms"});
  const auto kind = p.enum_field<WatchdogKind>(
      *it, "/watchdog", "kind", true,
      [](std::string_view v) -> std::optional<WatchdogKind> {
        for (std::size_t i = 0; i < kWatchdogNames.size(); ++i)
          if (kWatchdogNames[i] == v) return static_cast<WatchdogKind>(i);
        return std::nullopt;
      },
      "watchdog kind", "counter, any_write, none");
  if (!kind) return;
  if (*kind != WatchdogKind::any_write)
    for (const char* key : {"refresh", "period_ms", "timeout_ms"})
      if (it->contains(key))
        p.fail(std::string("/watchdog/") + key,
               *kind == WatchdogKind::counter ? "a counter's timing is on the heartbeat signal (period_ms, timeout_ms)"
                                              : "applies to kind any_write only");
  if (*kind == WatchdogKind::counter) {
    if (!heartbeat) p.fail("/watchdog/kind", "counter needs a heartbeat signal (with period_ms and timeout_ms)");
    return;
  }
  if (heartbeat) {
    p.fail("/watchdog/kind", "the profile maps a heartbeat signal, which is a counter watchdog; " +
                                 std::string(kWatchdogNames[static_cast<std::size_t>(*kind)]) +
                                 " contradicts it (remove one)");
    return;
  }
  if (*kind == WatchdogKind::none) {
    profile.watchdog = WatchdogSpec{};
    return;
  }
  const auto refresh = p.string_field(*it, "/watchdog", "refresh", true);
  const auto period = p.integer_field(*it, "/watchdog", "period_ms", 1, kMaxMs, true);
  const auto timeout = p.integer_field(*it, "/watchdog", "timeout_ms", 1, kMaxMs, true);
  if (refresh) {
    const ProfileSignal* s = profile.find(*refresh);
    const SignalSpec* spec = find_signal_spec(profile.kind, *refresh);
    if (!spec || spec->role != SignalRole::command)
      p.fail("/watchdog/refresh", in_quotes(*refresh) + " is not a command signal of kind " +
                                      std::string(name(profile.kind)));
    else if (!s)
      p.fail("/watchdog/refresh", in_quotes(*refresh) + " is not mapped by this profile");
  }
  if (period && timeout && *timeout <= *period)
    p.fail("/watchdog/timeout_ms", "must exceed period_ms (" + std::to_string(*period) +
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

std::string json_pointer_token(std::string_view key) {
  std::string out;
  for (const char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

ProfileParseResult parse_device_profile(const synbench::Json& doc) {
  Parser p;
  if (!doc.is_object()) {
    p.fail("", "a profile must be a JSON object");
    return {std::nullopt, std::move(p.errors)};
  }
  p.reject_unknown(doc, "", {"name", "description", "kind", "unit_id", "word_order", "byte_order", "signals",
                             "watchdog", "meter", "poll_period_ms", "time_base_Hz", "f0_Hz", "kf_Hz_per_A"});

  DeviceProfile profile;
  profile.name = p.string_field(doc, "", "name", true).value_or("");
  profile.description = p.string_field(doc, "", "description", false).value_or("");
  const auto kind = p.enum_field<DeviceKind>(doc, "", "kind", true, parse_device_kind, "device kind",
                                             "synrm_drive, load_drive, vfc_meter");
  const auto unit_id = p.integer_field(doc, "", "unit_id", kMinUnitId, kMaxUnitId, true);
  const auto word_order = p.enum_field<WordOrder>(doc, "", "word_order", false, parse_word_order, "word order",
                                                  "big, little");
  const auto byte_order = p.enum_field<ByteOrder>(doc, "", "byte_order", false, parse_byte_order, "byte order",
                                                  "big, little");

  const auto signals = doc.find("signals");
  if (signals == doc.end()) {
    p.fail("/signals", "required field is missing");
  } else if (!signals->is_object()) {
    p.fail("/signals", "must be an object of signal name: mapping");
  } else if (kind) {
    // Without a valid kind the signal names cannot be judged, so signals wait for that fix.
    profile.kind = *kind;
    profile.unit_id = static_cast<std::uint8_t>(unit_id.value_or(kMinUnitId));
    const Parser::Defaults defaults{profile.unit_id, word_order.value_or(WordOrder::big),
                                    byte_order.value_or(ByteOrder::big)};
    for (const auto& [key, value] : signals->items()) {
      if (is_comment(key)) continue;
      const std::string path = "/signals/" + json_pointer_token(key);
      const SignalSpec* spec = find_signal_spec(*kind, key);
      if (!spec) {
        p.fail(path, "unknown signal for kind " + std::string(name(*kind)) + " (docs/device-profile.md lists them)");
        continue;
      }
      if (auto s = p.signal(*spec, value, path, defaults)) profile.signals.push_back(std::move(*s));
    }
    check_overlaps(p, profile.signals);
    parse_watchdog(p, doc, profile);
    for (const SignalSpec& spec : signal_catalogue(*kind))
      if (spec.required && !signals->contains(spec.name))
        p.fail("/signals/" + json_pointer_token(spec.name),
               "required signal of kind " + std::string(name(*kind)) + " is missing");
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
