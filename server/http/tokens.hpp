// Bearer tokens of the daemon: DATA_DIR/tokens.json holds the SHA-256 of each token with its
// role (never the token). Tokens are 256 random bits; they are compared digest to digest in
// constant time, and reloaded when the file changes so `synbench token create` needs no restart.
#pragma once

#include <chrono>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "drivers/json_reader.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

struct TokenEntry {
  std::string sha256;  // hex digest of the token
  Role role = Role::viewer;
  std::string created;  // ISO 8601 UTC
};

class TokenStore {
 public:
  explicit TokenStore(std::filesystem::path file) : file_(std::move(file)) {}

  // Creates a token of `role`, appends its digest to the file (0600, written atomically) and
  // returns the token: the only time it exists in clear.
  std::string create(Role role, std::error_code& ec);
  // Loads the file; a missing file is an empty store. A broken file keeps the tokens loaded
  // before and says why in load_errors(): every problem at its JSON pointer.
  std::error_code load();
  std::vector<drivers::JsonError> load_errors() const;
  // The same, joined with "; " ("/tokens/0/role: unknown role 'admin' (expected viewer, operator)").
  std::string load_error() const;
  bool empty() const;
  // Role of `token` and its label ("token-" + 8 digits of its digest), or nullopt. Reloads the
  // file first when its modification time changed: looked at every kRecheck, and at once for a
  // token that matches none.
  std::optional<Identity> authenticate(std::string_view token);
  static constexpr std::chrono::milliseconds kRecheck{50};
  const std::filesystem::path& file() const { return file_; }

 private:
  std::error_code load_locked();
  // Stats the file (reloading it when it changed) and schedules the next look; returns true.
  bool reload_if_changed(std::chrono::steady_clock::time_point now);
  std::optional<Identity> match(const std::string& digest) const;  // over every entry, constant time
  std::chrono::steady_clock::time_point next_check_{};
  std::filesystem::path file_;
  mutable std::mutex mutex_;
  std::vector<TokenEntry> entries_;
  std::vector<drivers::JsonError> load_errors_;
  std::filesystem::file_time_type loaded_mtime_{};
};

// Equal lengths and bytes, in time independent of where they differ.
bool constant_time_equal(std::string_view a, std::string_view b);
// "sbt_" + 64 hex digits from the kernel's CSPRNG.
std::string new_token();
// Writes `text` to `path` with mode 0600, through a temporary file and rename.
std::error_code write_private_file(const std::filesystem::path& path, const std::string& text);

}  // namespace synbench::http
