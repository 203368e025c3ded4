// A directory of device profiles, one for each device kind: how `synbench emulate --profiles
// DIR` finds the maps it serves. Every *.json file directly in DIR (sorted by name, not
// recursive) whose top-level object has a "kind" member is a profile and must be valid; other
// JSON files (a bench config kept beside the profiles) are skipped. Exactly one profile of each
// kind (synrm_drive, load_drive, vfc_meter) is required.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

// A problem in one file of the directory (or, for a missing kind, in the directory itself).
struct FileError {
  std::string file;
  ProfileError error;
};

struct ProfileDirResult {
  std::optional<std::vector<DeviceProfile>> profiles;  // in kDeviceKinds order; set exactly when errors is empty
  std::vector<std::filesystem::path> files;            // the files they came from, in the same order
  std::vector<FileError> errors;
};

ProfileDirResult load_profile_dir(const std::filesystem::path& dir);

}  // namespace synbench::drivers
