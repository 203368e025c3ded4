// Probing a device: one single-signal ReadPlan per readable signal, through a bus wrapper that
// keeps the words the device answered, so the raw registers and the decoded value come from one
// read and one decoding (SignalIo's), and a value that does not decode is shown with its words
// and SignalIo's own reason (the same message the bench would log).
#include "drivers/profile_devices/probe.hpp"

#include <cmath>
#include <sstream>
#include <string_view>

#include "drivers/profile/register_codec.hpp"
#include "drivers/profile/signal_codes.hpp"
#include "drivers/profile_devices/signal_io.hpp"

namespace synbench::drivers {
namespace {

// Passes reads through and keeps the answer of the last one; refuses writes, so the probe
// cannot write even by mistake.
class RecordingBus final : public RegisterBus {
 public:
  explicit RecordingBus(RegisterBus& bus) : bus_(bus) {}

  std::error_code read_bits(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                            std::span<std::uint8_t> out) override {
    last.clear();
    const auto ec = bus_.read_bits(unit_id, kind, address, out);
    if (!ec) last.assign(out.begin(), out.end());
    return ec;
  }
  std::error_code read_registers(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                 std::span<std::uint16_t> out) override {
    last.clear();
    const auto ec = bus_.read_registers(unit_id, kind, address, out);
    if (!ec) last.assign(out.begin(), out.end());
    return ec;
  }
  std::error_code write_bits(std::uint8_t, std::uint16_t, std::span<const std::uint8_t>) override {
    return make_error_code(errc::not_supported);
  }
  std::error_code write_registers(std::uint8_t, std::uint16_t, std::span<const std::uint16_t>) override {
    return make_error_code(errc::not_supported);
  }
  BusStats stats() const override { return bus_.stats(); }
  int last_exception_code() const override { return bus_.last_exception_code(); }
  std::string last_error() const override { return bus_.last_error(); }
  std::string name() const override { return bus_.name(); }

  std::vector<std::uint16_t> last;

 private:
  RegisterBus& bus_;
};

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string label_of(DeviceKind kind, const ProfileSignal& s, double code) {
  if (!is_enumerated(kind, s)) return {};
  const SignalSpec* spec = find_signal_spec(kind, s.name);
  if (!spec || !(code >= 0) || code >= static_cast<double>(spec->labels.size()) || code != std::floor(code))
    return "code " + number(code);
  return std::string(spec->labels[static_cast<std::size_t>(code)]);
}

}  // namespace

std::vector<ProbeRow> probe_device(RegisterBus& bus, const DeviceProfile& profile) {
  RecordingBus recorder(bus);
  SignalIo io(recorder, profile);
  std::vector<ProbeRow> rows;
  for (const ProfileSignal& s : profile.signals) {
    if (!s.readable()) continue;
    ProbeRow row;
    row.device = profile.kind;
    row.profile = profile.name;
    row.signal = s.name;
    row.table = s.kind;
    row.address = s.address;
    row.count = static_cast<std::uint16_t>(is_bit_kind(s.kind) ? 1 : address_width(s.encoding.type) * s.values_count());
    row.unit_id = s.unit_id;
    row.unit = s.unit;
    const std::string_view name = s.name;
    const ReadPlan plan(profile, std::span<const std::string_view>(&name, 1));
    double value = 0;
    const auto ec = io.read(plan, std::span(&value, 1));
    row.raw = recorder.last;
    if (ec) {
      // Words that arrived and do not decode, or a request that failed on the link: SignalIo
      // names the place (device, signal, table, address, mask, unit id), the raw words and why.
      row.error = io.last_error().empty() ? ec.message() : io.last_error();
    } else {
      row.value = value;
      row.label = label_of(profile.kind, s, value);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace synbench::drivers
