// How `synbench profile check` and `synbench bench check` print a problem: "FILE: /pointer:
// reason" (or "FILE: reason" for the whole file), one per line, so every problem names the file
// it is in and the place in it.
#pragma once

#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "drivers/profile/device_profile.hpp"

namespace synbench::cli {

// One problem as "FILE: /pointer: reason".
std::string problem_text(const std::string& file, const drivers::ProfileError& e);
void print_problems(std::ostream& out, const std::string& file, const std::vector<drivers::ProfileError>& errors);

// "1" or "1, 4": the unit ids a profile's signals use.
std::string unit_ids(const drivers::DeviceProfile& p);

}  // namespace synbench::cli
