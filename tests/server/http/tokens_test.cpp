// Tokens: SHA-256 vectors, constant-time compare, the tokens file (digests only, 0600, reload).
#include "server/http/tokens.hpp"

#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include <algorithm>
#include <thread>
#include <gtest/gtest.h>

#include "server/http/sha256.hpp"

namespace synbench::http {
namespace {

std::filesystem::path temp_dir() {
  auto p = std::filesystem::temp_directory_path() / ("synbench-tokens-" + std::to_string(::getpid()) + "-" +
                                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

TEST(Sha256, FipsVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Tokens, ConstantTimeEqual) {
  EXPECT_TRUE(constant_time_equal("abc", "abc"));
  EXPECT_FALSE(constant_time_equal("abc", "abd"));
  EXPECT_FALSE(constant_time_equal("abc", "abcd"));
}

TEST(Tokens, NewTokensAreRandomAndWellFormed) {
  const auto a = new_token(), b = new_token();
  EXPECT_NE(a, b);
  EXPECT_EQ(a.size(), 4u + 64u);
  EXPECT_EQ(a.rfind("sbt_", 0), 0u);
}

TEST(Tokens, FileHoldsDigestsOnlyWithPrivateMode) {
  const auto dir = temp_dir();
  TokenStore store(dir / "tokens.json");
  std::error_code ec;
  const auto op = store.create(Role::operator_, ec);
  ASSERT_FALSE(ec);
  const auto view = store.create(Role::viewer, ec);
  ASSERT_FALSE(ec);
  std::ifstream in(dir / "tokens.json");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().find(op), std::string::npos);
  EXPECT_NE(text.str().find(sha256_hex(op)), std::string::npos);
  struct stat st{};
  ASSERT_EQ(::stat((dir / "tokens.json").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);

  TokenStore reader(dir / "tokens.json");
  ASSERT_FALSE(reader.load());
  EXPECT_EQ(reader.authenticate(op)->role, Role::operator_);
  EXPECT_EQ(reader.authenticate(op)->id, "token-" + sha256_hex(op).substr(0, 8));
  EXPECT_EQ(reader.authenticate(view)->role, Role::viewer);
  EXPECT_FALSE(reader.authenticate("sbt_nope"));
  EXPECT_FALSE(reader.authenticate(""));
  std::filesystem::remove_all(dir);
}

TEST(Tokens, ReloadsWhenAnotherProcessAddsOne) {
  const auto dir = temp_dir();
  TokenStore daemon(dir / "tokens.json");
  std::error_code ec;
  daemon.create(Role::operator_, ec);
  ASSERT_FALSE(ec);
  TokenStore cli(dir / "tokens.json");
  // File times may be coarse; make the change visible as a new modification time.
  std::filesystem::last_write_time(dir / "tokens.json", std::filesystem::file_time_type::clock::now() - std::chrono::hours(1));
  const auto added = cli.create(Role::viewer, ec);
  ASSERT_FALSE(ec);
  ASSERT_TRUE(daemon.authenticate(added));
  EXPECT_EQ(daemon.authenticate(added)->role, Role::viewer);
  std::filesystem::remove_all(dir);
}

// A token removed by another process (revoked) is refused once the daemon's store has looked at
// the file again: within TokenStore::kRecheck of the change, not on a stat per request.
TEST(Tokens, ARevokedTokenIsRefusedWithinTheRecheck) {
  const auto dir = temp_dir();
  TokenStore daemon(dir / "tokens.json");
  std::error_code ec;
  const auto op = daemon.create(Role::operator_, ec);
  ASSERT_FALSE(ec);
  TokenStore cli(dir / "tokens.json");
  std::filesystem::last_write_time(dir / "tokens.json", std::filesystem::file_time_type::clock::now() - std::chrono::hours(1));
  const auto view = cli.create(Role::viewer, ec);
  ASSERT_FALSE(ec);
  ASSERT_TRUE(daemon.authenticate(view));  // an unknown token looks at once
  ASSERT_TRUE(daemon.authenticate(op));
  // Revoked: the file holds the operator's token only.
  std::filesystem::last_write_time(dir / "tokens.json", std::filesystem::file_time_type::clock::now() - std::chrono::hours(2));
  auto doc = synbench::Json::parse(std::ifstream(dir / "tokens.json"));
  auto& list = doc["tokens"];
  list.erase(std::remove_if(list.begin(), list.end(), [](const auto& t) { return t["role"] == "viewer"; }), list.end());
  std::ofstream(dir / "tokens.json") << doc.dump();
  std::this_thread::sleep_for(TokenStore::kRecheck + std::chrono::milliseconds(20));
  EXPECT_FALSE(daemon.authenticate(view)) << "revoked, refused after the recheck";
  EXPECT_TRUE(daemon.authenticate(op));
  std::filesystem::remove_all(dir);
}

TEST(Tokens, BrokenFileIsAnError) {
  const auto dir = temp_dir();
  std::ofstream(dir / "tokens.json") << "{not json";
  TokenStore store(dir / "tokens.json");
  EXPECT_TRUE(store.load());
  EXPECT_NE(store.load_error().find("not valid JSON"), std::string::npos) << store.load_error();
  std::filesystem::remove_all(dir);
}

// Three mistakes in one tokens file: all three reported, each at its JSON pointer; the store
// keeps the tokens it had and authenticates none from the broken file.
TEST(Tokens, BrokenFileNamesEveryMistakeAtItsPointer) {
  const auto dir = temp_dir();
  const std::string good(64, 'a');
  std::ofstream(dir / "tokens.json") << R"({"tokens": [{"sha256": ")" << good << R"(", "role": "admin"},
    {"role": "viewer", "_note": "fine"}, {"sha256": "sbt_cleartext", "role": "operator", "expires": 1}]})";
  TokenStore store(dir / "tokens.json");
  EXPECT_EQ(store.load(), std::make_error_code(std::errc::invalid_argument));
  const std::vector<drivers::JsonError> want{
      {"/tokens/0/role", "unknown role 'admin' (expected viewer, operator)"},
      {"/tokens/1/sha256", "required field is missing"},
      {"/tokens/2/expires", "unknown field"},
      {"/tokens/2/sha256", "must be 64 lower-case hex digits (the token's SHA-256, never the token)"},
  };
  EXPECT_EQ(store.load_errors(), want);
  EXPECT_EQ(store.load_error().rfind("/tokens/0/role: unknown role 'admin' (expected viewer, operator); /tokens/1/", 0), 0u)
      << store.load_error();
  EXPECT_TRUE(store.empty());

  std::ofstream(dir / "tokens.json") << R"({"token": []})";
  EXPECT_TRUE(store.load());
  const std::vector<drivers::JsonError> root{{"/token", "unknown field"}, {"/tokens", "required field is missing"}};
  EXPECT_EQ(store.load_errors(), root);
  std::filesystem::remove_all(dir);
}

// A good file loads with no errors left from a broken one before.
TEST(Tokens, GoodFileClearsTheErrors) {
  const auto dir = temp_dir();
  std::ofstream(dir / "tokens.json") << R"({"tokens": 5})";
  TokenStore store(dir / "tokens.json");
  EXPECT_TRUE(store.load());
  EXPECT_EQ(store.load_error(), "/tokens: must be a list");
  std::error_code ec;
  std::filesystem::remove(dir / "tokens.json");
  const auto token = store.create(Role::viewer, ec);
  ASSERT_FALSE(ec);
  EXPECT_FALSE(store.load());
  EXPECT_EQ(store.load_error(), "");
  ASSERT_TRUE(store.authenticate(token));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace synbench::http
