// Token file handling; see tokens.hpp.
#include "server/http/tokens.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "drivers/json.hpp"

#include "drivers/json_file.hpp"
#include "drivers/json_reader.hpp"
#include "server/http/sha256.hpp"

namespace synbench::http {

bool constant_time_equal(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    diff = static_cast<unsigned char>(diff | (static_cast<unsigned char>(a[i]) ^ static_cast<unsigned char>(b[i])));
  return diff == 0;
}

std::string new_token() {
  unsigned char bytes[32];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category(), "getrandom");
    }
    got += static_cast<std::size_t>(n);
  }
  std::string out = "sbt_";
  char buf[3];
  for (unsigned char b : bytes) {
    std::snprintf(buf, sizeof buf, "%02x", b);
    out += buf;
  }
  return out;
}

std::error_code write_private_file(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return {errno, std::generic_category()};
  ::fchmod(fd, 0600);  // an older temporary file may have had wider permissions
  std::size_t off = 0;
  while (off < text.size()) {
    const ssize_t n = ::write(fd, text.data() + off, text.size() - off);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::error_code ec(errno, std::generic_category());
      ::close(fd);
      return ec;
    }
    off += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) return {errno, std::generic_category()};
  if (::rename(tmp.c_str(), path.c_str()) != 0) return {errno, std::generic_category()};
  return {};
}

namespace {

// The roles a token may carry ("anyone" is no token at all), by index.
constexpr std::array<std::string_view, 2> kTokenRoleNames{"viewer", "operator"};
constexpr std::array<Role, 2> kTokenRoles{Role::viewer, Role::operator_};

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

std::error_code TokenStore::load() {
  std::lock_guard lock(mutex_);
  return load_locked();
}

std::error_code TokenStore::load_locked() {
  std::error_code ec;
  load_errors_.clear();
  if (!std::filesystem::exists(file_, ec)) {
    entries_.clear();
    return {};
  }
  // Through the shared reader: a directory, a device, a huge or deeply nested file, bytes that
  // are not UTF-8 or an overflowing number are a refusal, never an exception.
  const drivers::JsonParsed read = drivers::read_json_file(file_);
  if (!read.ok()) {
    load_errors_.push_back({"", read.error});
    std::error_code type_ec;
    if (std::filesystem::is_directory(file_, type_ec)) return std::make_error_code(std::errc::is_a_directory);
    if (read.error.find(": cannot open: ") != std::string::npos) return std::make_error_code(std::errc::permission_denied);
    return std::make_error_code(std::errc::invalid_argument);
  }
  // Every problem at once, each at its JSON pointer, in the wording of the other loaders.
  drivers::JsonReader reader;
  const drivers::JsonNode doc = drivers::read_root(read.doc, reader);
  std::vector<TokenEntry> entries;
  if (doc.object()) {
    doc.reject_unknown({"tokens"});
    if (const auto tokens = doc["tokens"].required().list()) {
      for (const auto& t : *tokens) {
        if (!t.object()) continue;
        t.reject_unknown({"sha256", "role", "created"});
        auto sha = t["sha256"].required().text(true);
        if (sha && (sha->size() != 64 || sha->find_first_not_of("0123456789abcdef") != std::string::npos)) {
          t["sha256"].fail("must be 64 lower-case hex digits (the token's SHA-256, never the token)");
          sha.reset();
        }
        const auto role = t["role"].required().choice<std::size_t>(kTokenRoleNames, "role");
        // "created" is informative only, but a wrong type is a mistake in the file like any other.
        const auto created = t["created"].text();
        if (sha && role) entries.push_back({*sha, kTokenRoles[*role], created.value_or(std::string())});
      }
    }
  }
  if (!reader.ok()) {
    load_errors_ = std::move(reader.errors);
    return std::make_error_code(std::errc::invalid_argument);
  }
  entries_ = std::move(entries);
  loaded_mtime_ = std::filesystem::last_write_time(file_, ec);
  return {};
}

std::string TokenStore::load_error() const {
  std::lock_guard lock(mutex_);
  std::string all;
  for (const auto& e : load_errors_) all += (all.empty() ? "" : "; ") + (e.pointer.empty() ? e.reason : drivers::to_string(e));
  return all;
}

std::vector<drivers::JsonError> TokenStore::load_errors() const {
  std::lock_guard lock(mutex_);
  return load_errors_;
}

bool TokenStore::empty() const {
  std::lock_guard lock(mutex_);
  return entries_.empty();
}

std::string TokenStore::create(Role role, std::error_code& ec) {
  std::lock_guard lock(mutex_);
  ec = load_locked();  // keep tokens another process added meanwhile
  if (ec) return {};
  const std::string token = new_token();
  entries_.push_back({sha256_hex(token), role, utc_now()});
  synbench::Json doc = {{"tokens", synbench::Json::array()}};
  for (const auto& e : entries_) doc["tokens"].push_back({{"sha256", e.sha256}, {"role", role_name(e.role)}, {"created", e.created}});
  std::error_code mk;
  if (file_.has_parent_path()) std::filesystem::create_directories(file_.parent_path(), mk);
  ec = write_private_file(file_, doc.dump(2) + "\n");
  if (ec) return {};
  std::error_code te;
  loaded_mtime_ = std::filesystem::last_write_time(file_, te);
  return token;
}

std::optional<Identity> TokenStore::authenticate(std::string_view token) {
  std::lock_guard lock(mutex_);
  // The file is looked at (a stat) at most every kRecheck while tokens match, not on each of
  // tens of thousands of requests a second: a removed (revoked) token is refused from the
  // next request after that. A token that matches none looks again at once, so one just
  // created by `synbench token create` works on its first request.
  const auto now = std::chrono::steady_clock::now();
  const bool looked = now >= next_check_ && reload_if_changed(now);
  const std::string digest = sha256_hex(token);
  std::optional<Identity> found = match(digest);
  if (!found && !looked && reload_if_changed(now)) found = match(digest);
  return found;
}

bool TokenStore::reload_if_changed(std::chrono::steady_clock::time_point now) {
  next_check_ = now + kRecheck;
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(file_, ec);
  if (!ec && mtime != loaded_mtime_) load_locked();  // a broken file keeps the tokens we had
  return true;
}

std::optional<Identity> TokenStore::match(const std::string& digest) const {
  std::optional<Identity> found;
  // Every entry is compared, so the time taken says nothing about which one matched.
  for (const auto& e : entries_)
    if (constant_time_equal(digest, e.sha256)) found = Identity{e.role, "token-" + digest.substr(0, 8)};
  return found;
}

}  // namespace synbench::http
