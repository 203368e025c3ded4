// Test fixtures over the shipped device profiles: the default profile of each kind, parsed, and
// a profile file as raw JSON (for tests that edit a document before loading it).
#pragma once

#include <filesystem>
#include <fstream>
#include <vector>

#include "drivers/json.hpp"
#include "drivers/profile/device_profile.hpp"

namespace synbench::testing {

inline std::vector<drivers::DeviceProfile> default_profiles() {
  std::vector<drivers::DeviceProfile> out;
  for (auto k : drivers::kDeviceKinds)
    out.push_back(*drivers::load_device_profile(drivers::default_profile_path(k)).profile);
  return out;
}

inline synbench::Json json_doc(const std::filesystem::path& p) {
  std::ifstream in(p);
  return synbench::Json::parse(in);
}

}  // namespace synbench::testing
