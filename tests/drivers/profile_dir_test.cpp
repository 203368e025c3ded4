// Tests of a profile directory: the three kinds found by their "kind" whatever the file names,
// other JSON skipped, and a missing, doubled or broken profile named by its file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "drivers/profile/profile_dir.hpp"

namespace synbench::drivers {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  TempDir() : path(fs::temp_directory_path() / ("synbench_profile_dir_" + std::to_string(::getpid()) + "_" +
                                                ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  void copy_default(DeviceKind k, const std::string& as) { fs::copy_file(default_profile_path(k), path / as); }
  void write(const std::string& name, const std::string& text) { std::ofstream(path / name) << text; }
  fs::path path;
};

std::string dump(const ProfileDirResult& r) {
  std::string s;
  for (const auto& e : r.errors) s += e.file + ": " + e.error.pointer + ": " + e.error.reason + "\n";
  return s;
}

TEST(ProfileDir, FindsEachKindByItsKind) {
  TempDir d;
  d.copy_default(DeviceKind::vfc_meter, "a_meter.json");
  d.copy_default(DeviceKind::synrm_drive, "b_drive.json");
  d.copy_default(DeviceKind::load_drive, "c_load.json");
  d.write("bench.json", R"({"links": {}, "devices": {}})");  // not a profile: skipped
  d.write("notes.txt", "not json");
  const ProfileDirResult r = load_profile_dir(d.path);
  ASSERT_TRUE(r.profiles) << dump(r);
  ASSERT_EQ(r.profiles->size(), 3u);
  EXPECT_EQ((*r.profiles)[0].kind, DeviceKind::synrm_drive);
  EXPECT_EQ((*r.profiles)[1].kind, DeviceKind::load_drive);
  EXPECT_EQ((*r.profiles)[2].kind, DeviceKind::vfc_meter);
  EXPECT_EQ(r.files[0], d.path / "b_drive.json");
}

TEST(ProfileDir, MissingDoubledAndBrokenProfilesAreNamed) {
  TempDir d;
  d.copy_default(DeviceKind::synrm_drive, "one.json");
  d.copy_default(DeviceKind::synrm_drive, "two.json");
  d.write("broken.json", R"({"kind": "load_drive", "name": "x", "unit_id": 1, "signals": {"state": {"register": "input", "address": -1}}})");
  d.write("syntax.json", "{");
  const ProfileDirResult r = load_profile_dir(d.path);
  EXPECT_FALSE(r.profiles);
  const std::string text = dump(r);
  EXPECT_NE(text.find((d.path / "two.json").string() + ": /kind: a second synrm_drive profile: " +
                      (d.path / "one.json").string() + " is one already"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find((d.path / "broken.json").string() + ": /signals/state/address: "), std::string::npos) << text;
  EXPECT_NE(text.find((d.path / "syntax.json").string() + ": : " + (d.path / "syntax.json").string()), std::string::npos) << text;
  EXPECT_NE(text.find("no vfc_meter profile"), std::string::npos) << text;
  EXPECT_FALSE(load_profile_dir(d.path / "one.json").profiles);  // a file, not a directory
}

}  // namespace
}  // namespace synbench::drivers
