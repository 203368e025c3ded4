// synbench: one executable, one subcommand per job.
#include <iostream>
#include <string>
#include <vector>

#include "server/cli/commands.hpp"
#include "synbench/version.hpp"

namespace {

const char* const kHelp = R"(usage: synbench <command> [options]

synbench runs efficiency experiments on a synchronous reluctance motor test bench, or on its
built-in twin.

commands:
  point     measure one operating point (in-process twin, or devices of a bench config)
  sweep     run a sweep plan on the twin or a bench config's drives, stored in SQLite, resumable
  config    print or check the twin's configuration
  emulate   serve the twin over Modbus TCP or RTU
  serve     run the daemon: REST API, WebSocket and dashboard over the twin or real drives
  bench     check a bench config and probe its devices, read its drives, clear their faults
  profile   check device profiles
  study     run a twin study's shard (plant deviations x a sweep), its status, its merged analysis
  report    write a sweep's report: one self-contained HTML file and the points CSV
  token     create a bearer token for the daemon

  synbench <command> --help    options of a command
  synbench --version           version
)";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kHelp;
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "synbench " << synbench::kVersion << "\n";
    return 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  if (command == "point") return synbench::cli::point_command(args);
  if (command == "config") return synbench::cli::config_command(args);
  if (command == "sweep") return synbench::cli::sweep_command(args);
  if (command == "emulate") return synbench::cli::emulate_command(args);
  if (command == "serve") return synbench::cli::serve_command(args);
  if (command == "token") return synbench::cli::token_command(args);
  if (command == "bench") return synbench::cli::bench_command(args);
  if (command == "profile") return synbench::cli::profile_command(args);
  if (command == "report") return synbench::cli::report_command(args);
  if (command == "study") return synbench::cli::study_command(args);
  std::cerr << "synbench: unknown command '" << command << "' (see synbench --help)\n";
  return 2;
}
