// `synbench bench check CONFIG [--probe]`: a bench config and the profiles it names validated
// together (every problem with its file and JSON pointer, plus the cross-checks of
// drivers/bench_check.hpp) and the telemetry values the supervisor's frozen check cannot watch,
// and with --probe every readable signal of every device read once
// over the config's own links (the buses `point --bench` uses), printed as a table.
#include <algorithm>
#include <array>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "drivers/json.hpp"

#include "drivers/bench_check.hpp"
#include "drivers/profile_devices/probe.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/profile_problems.hpp"

namespace synbench::cli {
namespace {

const drivers::DeviceProfile& profile_of(const drivers::BenchProfiles& p, drivers::DeviceKind k) {
  using drivers::DeviceKind;
  return k == DeviceKind::synrm_drive ? p.synrm_drive : k == DeviceKind::load_drive ? p.load_drive : p.vfc_meter;
}

std::string addresses(const drivers::ProbeRow& r) {
  return r.count > 1 ? std::to_string(r.address) + "-" + std::to_string(r.address + r.count - 1)
                     : std::to_string(r.address);
}

std::string raw_text(const drivers::ProbeRow& r) {
  if (r.raw.empty()) return "-";
  if (drivers::is_bit_kind(r.table)) return std::to_string(r.raw[0]);  // a coil or discrete input: one bit
  std::string s;
  char word[8];
  for (const std::uint16_t w : r.raw) {
    std::snprintf(word, sizeof word, "0x%04X", w);
    s += (s.empty() ? "" : " ") + std::string(word);
  }
  return s;
}

std::string value_text(const drivers::ProbeRow& r) {
  if (!r.value) return "error: " + r.error;
  // An enumerated signal's value is its label; the device's own code is in the raw column.
  if (!r.label.empty()) return r.label;
  std::ostringstream s;
  s << std::setprecision(7) << *r.value;
  if (!r.unit.empty()) s << " " << r.unit;
  return s.str();
}

void print_table(const std::vector<drivers::ProbeRow>& rows) {
  std::vector<std::array<std::string, 7>> lines{{"device", "signal", "table", "address", "unit_id", "raw", "value"}};
  for (const auto& r : rows)
    lines.push_back({std::string(drivers::name(r.device)), r.signal, std::string(drivers::name(r.table)), addresses(r),
                     std::to_string(r.unit_id), raw_text(r), value_text(r)});
  std::array<std::size_t, 7> width{};
  for (const auto& l : lines)
    for (std::size_t i = 0; i < l.size(); ++i) width[i] = std::max(width[i], l[i].size());
  for (const auto& l : lines) {
    std::string text;
    for (std::size_t i = 0; i < l.size(); ++i)
      text += i + 1 == l.size() ? l[i] : l[i] + std::string(width[i] - l[i].size() + 2, ' ');
    std::cout << text << "\n";
  }
}

synbench::Json row_json(const drivers::ProbeRow& r) {
  synbench::Json j{{"device", drivers::name(r.device)}, {"profile", r.profile}, {"signal", r.signal},
                   {"table", drivers::name(r.table)},   {"address", r.address}, {"count", r.count},
                   {"unit_id", r.unit_id},              {"raw", r.raw},         {"unit", r.unit}};
  j["value"] = r.value ? synbench::Json(*r.value) : synbench::Json(nullptr);
  j["label"] = r.label.empty() ? synbench::Json(nullptr) : synbench::Json(r.label);
  j["error"] = r.error.empty() ? synbench::Json(nullptr) : synbench::Json(r.error);
  return j;
}

}  // namespace

int bench_check_command(const std::vector<std::string>& argv) {
  std::string file;
  bool probe = false, json = false;
  try {
    Args a(argv, {"--probe", "--json", "--help"}, {"--bench"});
    if (a.has("--help")) {
      std::cout << kBenchHelp;
      return 0;
    }
    if (a.positional().size() > 1) throw UsageError(a.positional()[1], "unexpected argument");
    if (!a.positional().empty()) file = a.positional()[0];
    if (const auto b = a.text("--bench")) {
      if (!file.empty()) throw UsageError("--bench", "give the config once");
      file = *b;
    }
    if (file.empty()) throw UsageError("CONFIG", "is required");
    probe = a.has("--probe");
    json = a.has("--json");
  } catch (const UsageError& e) {
    std::cerr << "synbench bench check: " << e.what() << "\n";
    return 2;
  }

  drivers::BenchConfigResult r = drivers::load_bench_config(file);
  std::vector<drivers::ProfileError> errors = r.errors;
  std::optional<drivers::BenchProfiles> profiles;
  if (r.config) profiles = drivers::load_bench_profiles(*r.config, errors);
  if (profiles) {
    const auto more = drivers::check_bench(*r.config, *profiles);
    errors.insert(errors.end(), more.begin(), more.end());
  }
  if (!errors.empty()) {
    print_problems(std::cout, file, errors);
    return 1;
  }
  const drivers::BenchConfig& config = *r.config;
  synbench::Json out{{"file", file}, {"ok", true}, {"devices", synbench::Json::array()}};
  if (!json) std::cout << file << ": ok\n";
  for (const drivers::DeviceKind k : drivers::kDeviceKinds) {
    const drivers::DeviceProfile& p = profile_of(*profiles, k);
    const drivers::DeviceConfig& d = config.device(k);
    out["devices"].push_back({{"kind", drivers::name(k)}, {"profile", p.name}, {"profile_file", d.profile.string()},
                              {"link", d.link}, {"signals", p.signals.size()}, {"unit_ids", unit_ids(p)}});
    if (!json)
      std::cout << "  " << drivers::name(k) << ": " << p.name << " (" << d.profile.string() << "), link " << d.link
                << ", " << p.signals.size() << " signals, unit ids " << unit_ids(p) << "\n";
  }
  // Not a problem, but what the supervisor will not see: said before anyone relies on it.
  const auto blind = drivers::frozen_check_blind_spots(*profiles);
  out["frozen_check_unwatched"] = synbench::Json::array();
  for (const auto& b : blind)
    out["frozen_check_unwatched"].push_back(
        {{"signal", b.signal}, {"step", b.step}, {"noise", b.noise}, {"unit", b.unit}, {"reason", b.describe()}});
  if (!json && !blind.empty()) {
    std::cout << "  the frozen-telemetry check cannot watch:\n";
    for (const auto& b : blind) std::cout << "    " << b.describe() << "\n";
  }
  int status = 0;
  if (probe) {
    const drivers::BenchProfiles probed = *profiles;
    ConfiguredBench bench(config, std::move(*profiles), emulator::TwinConfig{});
    std::vector<drivers::ProbeRow> rows;
    for (const drivers::DeviceKind k : drivers::kDeviceKinds) {
      auto device_rows = drivers::probe_device(bench.bus(config.device(k).link), profile_of(probed, k));
      rows.insert(rows.end(), std::make_move_iterator(device_rows.begin()), std::make_move_iterator(device_rows.end()));
    }
    std::size_t failed = 0;
    for (const auto& row : rows) failed += row.value ? 0 : 1;
    if (json) {
      out["probe"] = synbench::Json::array();
      for (const auto& row : rows) out["probe"].push_back(row_json(row));
      out["ok"] = failed == 0;
    } else {
      std::cout << "probe over " << bench.describe() << ":\n";
      print_table(rows);
      std::cout << rows.size() - failed << " of " << rows.size() << " signals read\n";
    }
    if (failed) status = 1;
  }
  if (json) std::cout << out.dump() << "\n";
  return status;
}

}  // namespace synbench::cli
