// Translation of enumerated signals through the profile's `values`.
#include "drivers/profile/signal_codes.hpp"

#include <cmath>

#include "drivers/error.hpp"
#include "drivers/fault.hpp"

namespace synbench::drivers {
namespace {

std::span<const std::string_view> labels_of(DeviceKind kind, const ProfileSignal& s) {
  const SignalSpec* spec = find_signal_spec(kind, s.name);
  return spec ? spec->labels : std::span<const std::string_view>{};
}

bool is_index(double v, std::size_t n) {
  return v >= 0 && v == std::floor(v) && v < static_cast<double>(n);
}

// A device number with no label: the signal's catch-all, or a fault code's unknown.
std::error_code unlabelled(std::span<const std::string_view> labels, const ProfileSignal& s, double& code) {
  if (!s.otherwise.empty()) {
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (labels[i] == s.otherwise) {
        code = static_cast<double>(i);
        return {};
      }
  }
  if (is_fault_code(s)) {
    code = static_cast<double>(static_cast<int>(Fault::unknown));
    return {};
  }
  return make_error_code(errc::protocol);
}

}  // namespace

bool is_fault_code(const ProfileSignal& s) { return s.name == "fault_code" || s.name == "window_fault_code"; }

bool is_enumerated(DeviceKind kind, const ProfileSignal& s) { return !labels_of(kind, s).empty(); }

std::error_code to_bench_code(DeviceKind kind, const ProfileSignal& s, double device_value, double& code) {
  const auto labels = labels_of(kind, s);
  if (labels.empty()) {
    code = device_value;
    return {};
  }
  if (s.values.empty()) {
    if (!is_index(device_value, labels.size())) return unlabelled(labels, s, code);
    code = device_value;
    return {};
  }
  for (const EnumValue& v : s.values) {
    if (static_cast<double>(v.value) != device_value) continue;
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (labels[i] == v.label) {
        code = static_cast<double>(i);
        return {};
      }
  }
  return unlabelled(labels, s, code);
}

std::error_code to_device_value(DeviceKind kind, const ProfileSignal& s, double code, double& device_value) {
  const auto labels = labels_of(kind, s);
  if (labels.empty()) {
    device_value = code;
    return {};
  }
  if (!is_index(code, labels.size())) return make_error_code(errc::invalid_argument);
  if (s.values.empty()) {
    device_value = code;
    return {};
  }
  const std::string_view label = labels[static_cast<std::size_t>(code)];
  for (const EnumValue& v : s.values)
    if (v.label == label && v.written) {
      device_value = static_cast<double>(v.value);
      return {};
    }
  return make_error_code(errc::not_supported);
}

}  // namespace synbench::drivers
