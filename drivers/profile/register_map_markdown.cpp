// Markdown rendering of profiles and of the signal catalogue. The output is byte-stable (no
// locale, no stream formatting) because the docs are compared against it.
#include "drivers/profile/register_map_markdown.hpp"

#include <cmath>

#include "drivers/profile/number_format.hpp"

namespace synbench::drivers {
namespace {

constexpr std::string_view kNone = "—";

std::string cell(std::string_view s) {
  if (s.empty()) return std::string(kNone);
  std::string out;
  for (const char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// The byte order of a value written as the letters of its bytes, most significant first (A),
// in the order they travel: the usual shorthand of drive manuals.
std::string order(const RegisterEncoding& e) {
  if (e.type == ValueType::boolean) return std::string(kNone);
  const std::string hi = e.byte_order == ByteOrder::big ? "AB" : "BA";
  if (address_width(e.type) == 1) return hi;
  const std::string lo = e.byte_order == ByteOrder::big ? "CD" : "DC";
  return e.word_order == WordOrder::big ? hi + lo : lo + hi;
}

std::string limits(const RegisterEncoding& e) {
  if (e.type == ValueType::boolean) return std::string(kNone);
  const bool has_min = std::isfinite(e.min), has_max = std::isfinite(e.max);
  if (has_min && has_max) return format_number(e.min) + " .. " + format_number(e.max);
  if (has_min) return ">= " + format_number(e.min);
  if (has_max) return "<= " + format_number(e.max);
  return std::string(kNone);
}

std::string address(const ProfileSignal& s) {
  if (s.masked()) return std::to_string(s.address) + " mask " + std::to_string(s.mask);
  if (s.last_address() == s.address) return std::to_string(s.address);
  return std::to_string(s.address) + "-" + std::to_string(s.last_address());
}

std::string notes(DeviceKind kind, const ProfileSignal& s) {
  std::string out;
  for (const EnumValue& v : s.values) out += (out.empty() ? "" : ", ") + std::to_string(v.value) + " " + v.label;
  // Without "values" the device uses the bench's own codes.
  if (const SignalSpec* spec = find_signal_spec(kind, s.name); spec && s.values.empty())
    for (std::size_t i = 0; i < spec->labels.size(); ++i)
      out += (i == 0 ? "" : ", ") + std::to_string(i) + " " + std::string(spec->labels[i]);
  if (!s.otherwise.empty()) out += (out.empty() ? "" : ", ") + std::string("otherwise ") + s.otherwise;
  if (s.reset.mode == FaultResetMode::Mode::pulse) out += "pulse of " + std::to_string(s.reset.pulse_ms) + " ms";
  if (s.heartbeat)
    out += "write every " + std::to_string(s.heartbeat->period_ms) + " ms; trips after " +
           std::to_string(s.heartbeat->timeout_ms) + " ms unchanged";
  return out;
}

void device_table(std::string& md, const DeviceProfile& p) {
  md += "## " + p.name + "\n\n";
  md += "Kind `" + std::string(name(p.kind)) + "`, default unit id " + std::to_string(p.unit_id) + ".";
  if (!p.description.empty()) md += " " + p.description;
  md += "\n\n";
  md += "| Signal | Unit id | Table | Address | Type | Order | Scale / offset | Unit | Access | Limits | Role | Notes |\n";
  md += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ProfileSignal& s : p.signals) {
    const RegisterEncoding& e = s.encoding;
    const std::string scaling = e.type == ValueType::boolean
                                    ? std::string(kNone)
                                    : format_number(e.scale) + " / " + format_number(e.offset);
    md += "| `" + s.name + "` | " + std::to_string(s.unit_id) + " | " + std::string(name(s.kind)) + " | " +
          address(s) + " | " + std::string(name(e.type)) + (s.count ? " x " + std::to_string(s.count) : "") +
          " | " + order(e) + " | " + scaling + " | " +
          cell(s.unit) + " | " + std::string(name(s.access)) + " | " + limits(e) + " | " +
          std::string(name(s.role)) + " | " + cell(notes(p.kind, s)) + " |\n";
  }
  md += "\n";
}

}  // namespace

std::string render_register_map(std::span<const DeviceProfile> profiles) {
  std::string md =
      "# Register map\n\n"
      "Generated from the default device profiles in `drivers/profiles/` by `render_register_map()`\n"
      "(`drivers/profile/register_map_markdown.hpp`). Do not edit: `tests/drivers` fails when this\n"
      "file and the profiles disagree, and `SYNBENCH_REGENERATE_DOCS=1` on that test rewrites it.\n"
      "The profile format is described in [device-profile.md](device-profile.md).\n\n"
      "- Addresses are 0-based protocol addresses, as on the wire (holding register 0 is the one\n"
      "  some manuals call 40001).\n"
      "- Engineering value = raw * scale + offset.\n"
      "- Order shows the bytes of a value as transmitted, A being the most significant: `AB` and\n"
      "  `ABCD` are the Modbus standard (big-endian words, high word first).\n"
      "- Limits bound what the bench may write and what it accepts on reading; a value read outside\n"
      "  them is reported as a protocol error, never passed on.\n\n";
  for (const DeviceProfile& p : profiles) device_table(md, p);
  md.pop_back();  // one newline at the end of the file
  return md;
}

std::string render_signal_catalogue() {
  std::string md;
  for (const DeviceKind kind : kDeviceKinds) {
    md += "### `" + std::string(name(kind)) + "`\n\n";
    md += "| Signal | Role | Required | Unit | Meaning |\n";
    md += "|---|---|---|---|---|\n";
    for (const SignalSpec& s : signal_catalogue(kind)) {
      std::string meaning(s.doc);
      for (std::size_t i = 0; i < s.labels.size(); ++i)
        meaning += (i == 0 ? "; codes: " : ", ") + std::to_string(i) + " " + std::string(s.labels[i]);
      md += "| `" + std::string(s.name) + "` | " + std::string(name(s.role)) + " | " +
            (s.required ? "yes" : "no") + " | " + cell(s.unit) + " | " + cell(meaning) + " |\n";
    }
    md += "\n";
  }
  return md;
}

}  // namespace synbench::drivers
