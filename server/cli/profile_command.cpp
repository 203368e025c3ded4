// `synbench profile check FILE...`: validates device profiles (docs/device-profile.md) without a
// bench, every problem of every file at once, each naming its file and JSON pointer.
#include <iostream>

#include "drivers/profile/device_profile.hpp"
#include "server/cli/args.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/profile_problems.hpp"

namespace synbench::cli {

const char* const kProfileHelp = R"(usage: synbench profile check FILE...

Validates device profiles (docs/device-profile.md): every problem of every file, one per line,
as "FILE: /json/pointer: reason", and for each valid file one line:
"FILE: ok: NAME, KIND, N signals, unit ids LIST".

options:
  --help   this text

exit status: 0 every file is a valid profile, 1 a file has problems, 2 bad usage
)";

int profile_command(const std::vector<std::string>& argv) {
  std::vector<std::string> files;
  try {
    Args a(argv, {"--help"}, {});
    if (a.has("--help")) {
      std::cout << kProfileHelp;
      return 0;
    }
    if (a.positional().empty() || a.positional()[0] != "check") throw UsageError("ACTION", "give check");
    files.assign(a.positional().begin() + 1, a.positional().end());
    if (files.empty()) throw UsageError("FILE", "give at least one profile");
  } catch (const UsageError& e) {
    std::cerr << "synbench profile: " << e.what() << "\n";
    return 2;
  }
  bool ok = true;
  for (const std::string& file : files) {
    const drivers::ProfileParseResult r = drivers::load_device_profile(file);
    if (!r.profile) {
      print_problems(std::cout, file, r.errors);
      ok = false;
      continue;
    }
    const drivers::DeviceProfile& p = *r.profile;
    std::cout << file << ": ok: " << p.name << ", " << drivers::name(p.kind) << ", " << p.signals.size()
              << " signals, unit ids " << unit_ids(p) << "\n";
  }
  return ok ? 0 : 1;
}

}  // namespace synbench::cli
