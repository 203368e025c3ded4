// Resolving the device number served for each code of an enumerated signal: the label's own
// number, else (the profile's catch-all) a number the profile lists for no label, else the
// fallback state's number.
#include "emulator/modbus/served_codes.hpp"

#include <array>
#include <cstdint>

#include "drivers/profile/number_format.hpp"
#include "drivers/profile/register_codec.hpp"
#include "drivers/profile/signal_codes.hpp"
#include "drivers/profile/signal_catalogue.hpp"

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using drivers::ProfileSignal;

bool is_drive_state(const drivers::DeviceProfile& p, const ProfileSignal& s) {
  return s.name == "state" && (p.kind == DeviceKind::synrm_drive || p.kind == DeviceKind::load_drive);
}

// Whether the register can hold `device_value` as the profile encodes it (bits, type, limits).
bool encodable(const ProfileSignal& s, double device_value) {
  if (drivers::is_bit_kind(s.kind)) return device_value == 0 || device_value == 1;
  std::array<std::uint16_t, 2> w{0, 0};
  if (s.masked()) return !drivers::encode_field(s.encoding, s.mask, device_value, w[0]);
  return !drivers::encode_registers(s.encoding, device_value, std::span(w.data(), drivers::address_width(s.encoding.type)));
}

// The number served for bench code `code`: its label's first number, or for the profile's
// `otherwise` label the smallest number that reads as it (one the profile lists for no label).
std::optional<double> own_number(DeviceKind kind, const ProfileSignal& s, std::size_t code, std::string_view label) {
  double v = 0;
  if (!drivers::to_device_value(kind, s, static_cast<double>(code), v)) return v;
  if (s.otherwise != label) return std::nullopt;
  const std::uint32_t top = drivers::is_bit_kind(s.kind) ? 1u : s.masked() ? drivers::field_max(s.mask) : 65535u;
  for (std::uint32_t n = 0; n <= top; ++n) {
    double back = 0;
    if (!drivers::to_bench_code(kind, s, n, back) && back == static_cast<double>(code) && encodable(s, n)) return n;
  }
  return std::nullopt;
}

std::string where(const drivers::DeviceProfile& p) {
  return "profile '" + p.name + "' (" + std::string(drivers::name(p.kind)) + ")";
}

}  // namespace

std::string_view state_fallback(std::string_view label) {
  if (label == "stopping") return "running";
  if (label == "faulted") return "disabled";
  return {};
}

ServedCodes served_codes(const drivers::DeviceProfile& p, const ProfileSignal& s) {
  ServedCodes out;
  const drivers::SignalSpec* spec = drivers::find_signal_spec(p.kind, s.name);
  if (!spec || spec->labels.empty() || drivers::is_fault_code(s)) return out;
  const auto& labels = spec->labels;
  for (std::size_t c = 0; c < labels.size(); ++c) out.by_code.push_back(own_number(p.kind, s, c, labels[c]));
  if (!is_drive_state(p, s)) return out;
  const auto own = out.by_code;  // a fallback is to a state's own number, never to another fallback
  for (std::size_t c = 0; c < labels.size(); ++c) {
    if (own[c]) continue;
    const std::string_view to = state_fallback(labels[c]);
    for (std::size_t f = 0; f < labels.size(); ++f)
      if (!to.empty() && labels[f] == to && own[f]) out.by_code[c] = own[f];
    if (out.by_code[c])
      out.warnings.push_back(where(p) + ": signal state has no number for '" + std::string(labels[c]) +
                             "'; the emulator serves '" + std::string(to) + "' (" +
                             drivers::format_number(*out.by_code[c]) + ") in that state");
    else
      out.errors.push_back(where(p) + ": signal state has no number for '" + std::string(labels[c]) +
                           "' (nor an \"otherwise\"" + (to.empty() ? "" : ", nor for its fallback '" + std::string(to) + "'") +
                           "): the twin cannot show that state; map it");
  }
  return out;
}

ServedCodeNotes check_served_codes(const std::vector<drivers::DeviceProfile>& profiles) {
  ServedCodeNotes notes;
  for (const drivers::DeviceProfile& p : profiles)
    for (const ProfileSignal& s : p.signals) {
      if (!s.readable()) continue;
      auto c = served_codes(p, s);
      notes.warnings.insert(notes.warnings.end(), c.warnings.begin(), c.warnings.end());
      notes.errors.insert(notes.errors.end(), c.errors.begin(), c.errors.end());
    }
  return notes;
}

}  // namespace synbench::emulator
