// Tests of the shared JSON reader and the UTF-8 checks: every refusal is a reason naming the
// file and what is wrong, never an exception (number overflow, deep nesting, bytes that are not
// UTF-8, directories, devices, /proc/self/mem, FIFOs, oversize files).
#include "drivers/json_file.hpp"
#include "drivers/utf8.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace synbench::drivers {
namespace {

namespace fs = std::filesystem;

TEST(Utf8, FindsTheFirstBadByte) {
  EXPECT_FALSE(first_invalid_utf8(""));
  EXPECT_FALSE(first_invalid_utf8("plain ascii"));
  EXPECT_FALSE(first_invalid_utf8("\xC3\xA9t\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80"));  // été € 😀
  EXPECT_EQ(first_invalid_utf8("ab\xFF"), 2u);
  EXPECT_EQ(first_invalid_utf8("\xC3"), 0u);              // truncated
  EXPECT_EQ(first_invalid_utf8("x\xC0\xAF"), 1u);         // overlong '/'
  EXPECT_EQ(first_invalid_utf8("\xE0\x80\x80"), 0u);      // overlong
  EXPECT_EQ(first_invalid_utf8("\xED\xA0\x80"), 0u);      // a UTF-16 surrogate
  EXPECT_EQ(first_invalid_utf8("\xF4\x90\x80\x80"), 0u);  // above U+10FFFF
  EXPECT_EQ(first_invalid_utf8("\xF5\x80\x80\x80"), 0u);
  EXPECT_EQ(first_invalid_utf8("\x80"), 0u);              // a lone continuation byte
}

TEST(Utf8, EscapesOnlyTheBadBytes) {
  EXPECT_EQ(escape_invalid_utf8("a\xFF" "b\xC3\xA9"), "a\\xFFb\xC3\xA9");
  EXPECT_EQ(escape_invalid_utf8("\xC3"), "\\xC3");
  EXPECT_TRUE(is_valid_utf8(escape_invalid_utf8("\xFF\xFE\xC0\x80\xED\xA0\x80")));
}

TEST(JsonText, ParsesADocument) {
  const auto r = parse_json_text(R"({"a": [1, 2.5, "\u00e9"]})");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.doc["a"][2], "\xC3\xA9");
}

TEST(JsonText, RefusesWithAReason) {
  const struct {
    std::string text, reason;
  } cases[] = {
      {"{\"a\": \"\xFF\"}", "not valid UTF-8 at byte 7"},
      {"{\"a\": 1e309}", "number overflow"},
      {"{\"a\": -1e400}", "number overflow"},
      {"{\"a\": " + std::string(400, '9') + "}", "number overflow"},
      {std::string(65, '[') + std::string(65, ']'), "nested deeper than 64 levels at byte 64"},
      {std::string(1000000, '['), "nested deeper than 64 levels"},
      {"{\"a\": }", "not valid JSON: parse error at line 1, column 7"},
      {"\xC3\xA9", "not valid JSON"},  // valid UTF-8, not JSON: the message stays UTF-8
      {"{\"k\": \"\\ud800\"}", "not valid JSON"},
      {"", "not valid JSON"},
  };
  for (const auto& c : cases) {
    const auto r = parse_json_text(c.text);
    EXPECT_FALSE(r.ok()) << c.text.substr(0, 40);
    EXPECT_NE(r.error.find(c.reason), std::string::npos) << r.error;
    EXPECT_TRUE(is_valid_utf8(r.error)) << r.error;
    EXPECT_TRUE(r.doc.is_null());
  }
  // Brackets inside strings do not count as nesting.
  EXPECT_TRUE(parse_json_text("{\"a\": \"" + std::string(200, '[') + "\\\"\"}").ok());
}

class JsonFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("synbench-json-file-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  fs::path dir_;
};

TEST_F(JsonFile, ReadsARegularFile) {
  const auto r = read_json_file(write("ok.json", R"({"x": 1})"));
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.doc["x"], 1);
}

TEST_F(JsonFile, NamesThePathAndTheReason) {
  const auto expect = [](const fs::path& p, const std::string& reason) {
    const auto r = read_json_file(p);
    EXPECT_FALSE(r.ok()) << p;
    EXPECT_EQ(r.error.rfind(p.string() + ": ", 0), 0u) << r.error;
    EXPECT_NE(r.error.find(reason), std::string::npos) << r.error;
  };
  expect(dir_ / "missing.json", "cannot open: No such file or directory");
  expect(dir_, "a directory, not a regular file");
  expect("/dev/null", "a character device, not a regular file");
  expect("/proc/self/mem", "cannot read");
  expect(write("overflow.json", R"({"thermal": {"ambient_C": 1e309}})"), "number overflow");
  expect(write("utf8.json", "{\"a\": \"\xC3\x28\"}"), "not valid UTF-8 at byte 7");
  const fs::path fifo = dir_ / "fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect(fifo, "a FIFO, not a regular file");  // refused without waiting for a writer
}

TEST_F(JsonFile, CapsTheSize) {
  JsonLimits small;
  small.max_bytes = 1024;
  const auto p = write("big.json", "[" + std::string(2000, ' ') + "]");
  const auto r = read_json_file(p, small);
  EXPECT_NE(r.error.find("larger than 1 KiB"), std::string::npos) << r.error;
  EXPECT_TRUE(read_json_file(p).ok());
}

TEST_F(JsonFile, APathThatIsNotUtf8IsShownEscaped) {
  const auto r = read_json_file(dir_ / "bad\xFF.json");
  EXPECT_NE(r.error.find("bad\\xFF.json: cannot open"), std::string::npos) << r.error;
  EXPECT_TRUE(is_valid_utf8(r.error));
}

}  // namespace
}  // namespace synbench::drivers
