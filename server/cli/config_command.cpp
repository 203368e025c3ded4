// `synbench config`: prints the default twin config, its reference table, or checks a file.
#include "drivers/json.hpp"

#include <iostream>

#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/commands.hpp"

namespace synbench::cli {

const char* const kConfigHelp = R"(usage: synbench config [--defaults | --markdown | --check FILE]

  --defaults       print the full default twin config as JSON (keys in a section's
                   "_assumed" list are our calibration, not values from the thesis)
  --markdown       print the reference table of every key (docs/emulator-config.md)
  --check FILE     validate a config file; exit 2 naming the first bad key
  --help           this text
)";

int config_command(const std::vector<std::string>& argv) {
  try {
    Args a(argv, {"--defaults", "--markdown", "--help"}, {"--check"});
    if (a.has("--help") || argv.empty()) {
      std::cout << kConfigHelp;
      return 0;
    }
    if (!a.positional().empty()) throw UsageError(a.positional().front(), "unexpected argument");
    if (a.has("--defaults")) std::cout << emulator::to_json(emulator::TwinConfig{}).dump(2) << "\n";
    if (a.has("--markdown")) std::cout << emulator::markdown_reference(emulator::TwinConfig{});
    if (auto file = a.text("--check")) {
      emulator::load_twin_config_file(*file);
      std::cout << *file << ": ok\n";
    }
    return 0;
  } catch (const UsageError& e) {
    std::cerr << "synbench config: " << e.what() << "\n";
  } catch (const emulator::ConfigError& e) {
    std::cerr << "synbench config: " << e.what() << "\n";
  }
  return 2;
}

}  // namespace synbench::cli
