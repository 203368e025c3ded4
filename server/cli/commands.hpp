// The synbench subcommands. Each takes its own arguments (after the subcommand name) and
// returns the process exit status: 0 ok, 1 runtime failure, 2 bad usage, 3 faulted point.
#pragma once

#include <string>
#include <vector>

namespace synbench::cli {

int point_command(const std::vector<std::string>& args);
int config_command(const std::vector<std::string>& args);
int sweep_command(const std::vector<std::string>& args);
int emulate_command(const std::vector<std::string>& args);
int serve_command(const std::vector<std::string>& args);
int token_command(const std::vector<std::string>& args);
int bench_command(const std::vector<std::string>& args);
int bench_check_command(const std::vector<std::string>& args);  // `bench check ...`, after "check"
int profile_command(const std::vector<std::string>& args);
int report_command(const std::vector<std::string>& args);
int study_command(const std::vector<std::string>& args);

extern const char* const kPointHelp;
extern const char* const kConfigHelp;
extern const char* const kSweepHelp;
extern const char* const kEmulateHelp;
extern const char* const kServeHelp;
extern const char* const kTokenHelp;
extern const char* const kBenchHelp;
extern const char* const kProfileHelp;
extern const char* const kReportHelp;
extern const char* const kStudyHelp;

}  // namespace synbench::cli
