// Vendor-style variants of synbench's own drive profiles for tests: a control word of bits
// (enable, PWM scheme, fault reset) instead of coils, a status word whose bits give the state,
// fault codes in the vendor's numbers, and a watchdog other than the heartbeat counter. Built by
// editing the default profiles, so the rest of the map (windows, telemetry) stays the firmware's.
#pragma once

#include "drivers/json.hpp"

#include <fstream>
#include <stdexcept>
#include <string>

#include "drivers/profile/device_profile.hpp"

namespace synbench::testing {

inline synbench::Json default_profile_doc(drivers::DeviceKind kind) {
  std::ifstream in(drivers::default_profile_path(kind));
  return synbench::Json::parse(in);
}

inline drivers::DeviceProfile parse_or_throw(const synbench::Json& doc) {
  auto r = drivers::parse_device_profile(doc);
  if (!r.profile) {
    std::string why;
    for (const auto& e : r.errors) why += " '" + e.pointer + "': " + e.reason;
    throw std::runtime_error("test profile refused:" + why);
  }
  return *r.profile;
}

// The vendor's fault numbers (CiA 402 style); `with_watchdog` false leaves the watchdog's code
// out, so a watchdog trip reads as a code the profile has no label for.
inline synbench::Json vendor_fault_codes(bool with_watchdog = true) {
  synbench::Json v = {{"none", 0},           {"overcurrent", {0x2310, 0x2311}}, {"overvoltage", 0x3210},
                      {"undervoltage", 0x3220}, {"overspeed", 0x8400},          {"overtemperature", 0x4210},
                      {"estop", 0x5441},       {"link_loss", 0x8100},          {"load_drive", 0x7300}};
  if (with_watchdog) v["watchdog"] = 0x8130;
  return v;
}

// Control word at holding 40 (enable bit 0, pwm_scheme bit 4, fault_reset bit 7), status word
// at input 40 (state from mask 0x000B), vendor fault codes at input 41.
inline synbench::Json vendor_words(synbench::Json doc, const synbench::Json& reset, bool watchdog_code = true) {
  auto& s = doc["signals"];
  s["enable"] = {{"register", "holding"}, {"address", 40}, {"type", "u16"}, {"bit", 0}};
  s["pwm_scheme"] = {{"register", "holding"}, {"address", 40}, {"type", "u16"}, {"bit", 4},
                     {"values", {{"capwm", 0}, {"aspwm", 1}}}};
  s["fault_reset"] = {{"register", "holding"}, {"address", 40}, {"type", "u16"}, {"bit", 7}, {"access", "rw"},
                      {"reset", reset}};
  s["state"] = {{"register", "input"}, {"address", 40}, {"type", "u16"}, {"mask", 0x000B},
                {"values", {{"disabled", {0, 1}}, {"stopping", 2}, {"running", 3}, {"faulted", {8, 9, 10, 11}}}},
                {"otherwise", "faulted"}};
  s["fault_code"] = {{"register", "input"}, {"address", 41}, {"type", "u16"}, {"values", vendor_fault_codes(watchdog_code)}};
  return doc;
}

inline synbench::Json pulse_reset(int pulse_ms = 100) { return {{"mode", "pulse"}, {"pulse_ms", pulse_ms}}; }
inline synbench::Json level_reset() { return {{"mode", "level"}}; }

// The SynRM drive as a vendor drive: its words, and `watchdog` in place of the heartbeat.
inline synbench::Json vendor_synrm(const synbench::Json& reset, const synbench::Json& watchdog,
                                   bool watchdog_code = true) {
  synbench::Json doc = vendor_words(default_profile_doc(drivers::DeviceKind::synrm_drive), reset, watchdog_code);
  doc["name"] = "vendor SynRM drive";
  if (!watchdog.is_null()) {
    doc["signals"].erase("heartbeat");
    doc["watchdog"] = watchdog;
  }
  return doc;
}

// The load drive with its fault reset as a coil of the given mode and `watchdog` (null: keep the
// heartbeat counter).
inline synbench::Json vendor_load(const synbench::Json& reset, const synbench::Json& watchdog) {
  synbench::Json doc = default_profile_doc(drivers::DeviceKind::load_drive);
  doc["name"] = "vendor load drive";
  doc["signals"]["fault_reset"]["reset"] = reset;
  if (!watchdog.is_null()) {
    doc["signals"].erase("heartbeat");
    doc["watchdog"] = watchdog;
  }
  return doc;
}

inline synbench::Json any_write(const char* refresh, int period_ms = 250, int timeout_ms = 1000) {
  return {{"kind", "any_write"}, {"refresh", refresh}, {"period_ms", period_ms}, {"timeout_ms", timeout_ms}};
}
inline synbench::Json no_watchdog() { return {{"kind", "none"}}; }

}  // namespace synbench::testing
