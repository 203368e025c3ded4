// Finding and loading the profiles of a directory.
#include "drivers/profile/profile_dir.hpp"

#include <algorithm>
#include <array>

#include "drivers/json_file.hpp"

namespace synbench::drivers {

ProfileDirResult load_profile_dir(const std::filesystem::path& dir) {
  ProfileDirResult out;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    out.errors.push_back({dir.string(), {"", "not a directory"}});
    return out;
  }
  std::vector<std::filesystem::path> files;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".json" && it->is_regular_file(ec)) files.push_back(it->path());
  if (ec) {
    out.errors.push_back({dir.string(), {"", "cannot list: " + ec.message()}});
    return out;
  }
  std::sort(files.begin(), files.end());
  std::array<std::optional<DeviceProfile>, kDeviceKinds.size()> found;
  std::array<std::filesystem::path, kDeviceKinds.size()> from;
  for (const auto& file : files) {
    const JsonParsed read = read_json_file(file);
    if (!read.ok()) {
      out.errors.push_back({file.string(), {"", read.error}});
      continue;
    }
    if (!read.doc.is_object() || !read.doc.contains("kind")) continue;  // not a profile
    ProfileParseResult r = parse_device_profile(read.doc);
    if (!r.profile) {
      for (auto& e : r.errors) out.errors.push_back({file.string(), std::move(e)});
      continue;
    }
    const auto i = static_cast<std::size_t>(std::find(kDeviceKinds.begin(), kDeviceKinds.end(), r.profile->kind) -
                                            kDeviceKinds.begin());
    if (found[i]) {
      out.errors.push_back({file.string(), {"/kind", "a second " + std::string(name(r.profile->kind)) +
                                                         " profile: " + from[i].string() + " is one already"}});
      continue;
    }
    found[i] = std::move(*r.profile);
    from[i] = file;
  }
  for (std::size_t i = 0; i < kDeviceKinds.size(); ++i)
    if (!found[i])
      out.errors.push_back({dir.string(), {"", "no " + std::string(name(kDeviceKinds[i])) +
                                                   " profile (a *.json file with \"kind\": \"" +
                                                   std::string(name(kDeviceKinds[i])) + "\")"}});
  if (!out.errors.empty()) return out;
  out.profiles.emplace();
  for (std::size_t i = 0; i < kDeviceKinds.size(); ++i) {
    out.profiles->push_back(std::move(*found[i]));
    out.files.push_back(from[i]);
  }
  return out;
}

}  // namespace synbench::drivers
