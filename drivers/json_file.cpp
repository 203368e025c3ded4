// Reading and parsing JSON input without ever throwing; see json_file.hpp.
#include "drivers/json_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>

#include "drivers/utf8.hpp"

namespace synbench::drivers {
namespace {

std::string size_text(std::size_t bytes) {
  if (bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  if (bytes % (1u << 10) == 0) return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + " bytes";
}

// The byte where nesting first exceeds `max_depth`, brackets inside strings aside. A cheap
// scan before parsing: nlohmann parses any depth, but copying, dumping or validating the tree
// recurses once per level, so a file of a million '[' would overflow the stack later.
std::optional<std::size_t> too_deep(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

// "[json.exception.parse_error.101] parse error at line 1, ..." -> "parse error at line 1, ...".
std::string parser_message(const char* what) {
  std::string m = what;
  if (const auto b = m.find("] "); m.rfind("[json.exception.", 0) == 0 && b != std::string::npos) m = m.substr(b + 2);
  // The parser quotes what it last read, which may be a 400-digit number or end inside a
  // multi-byte character: shortened, and made UTF-8.
  constexpr std::size_t kMax = 240;
  if (m.size() > kMax) m = m.substr(0, kMax) + "...";
  return escape_invalid_utf8(m);
}

const char* file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

}  // namespace

JsonParsed parse_json_text(std::string_view text, const JsonLimits& limits) {
  JsonParsed out;
  if (const auto bad = first_invalid_utf8(text)) {
    out.error = "not valid UTF-8 at byte " + std::to_string(*bad);
    return out;
  }
  if (const auto deep = too_deep(text, limits.max_depth)) {
    out.error = "nested deeper than " + std::to_string(limits.max_depth) + " levels at byte " + std::to_string(*deep);
    return out;
  }
  try {
    out.doc = synbench::Json::parse(text);
  } catch (const synbench::Json::exception& e) {
    // parse_error for syntax, out_of_range for a number beyond a double's range (1e309).
    out.doc = nullptr;
    out.error = "not valid JSON: " + parser_message(e.what());
  }
  return out;
}

TextRead read_text_file(const std::filesystem::path& path, std::size_t max_bytes) {
  TextRead out;
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused just below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) {
    out.error = std::string("cannot open: ") + std::strerror(errno);
    return out;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    out.error = std::string("cannot read: ") + std::strerror(errno);
  } else if (!S_ISREG(st.st_mode)) {
    out.error = std::string(file_type(st.st_mode)) + ", not a regular file";
  } else if (static_cast<std::uintmax_t>(st.st_size) > max_bytes) {
    out.error = "larger than " + size_text(max_bytes);
  } else {
    // Read to the end rather than trust st_size: files under /proc say 0 and have content.
    char buf[65536];
    for (;;) {
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        out.error = std::string("cannot read: ") + std::strerror(errno);
        break;
      }
      if (n == 0) break;
      if (out.text.size() + static_cast<std::size_t>(n) > max_bytes) {
        out.error = "larger than " + size_text(max_bytes);
        break;
      }
      out.text.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  if (!out.error.empty()) out.text.clear();
  return out;
}

JsonParsed read_json_file(const std::filesystem::path& path, const JsonLimits& limits) {
  // The path itself may hold any byte; the message stays valid UTF-8.
  const std::string name = escape_invalid_utf8(path.string());
  TextRead file = read_text_file(path, limits.max_bytes);
  if (!file.error.empty()) return {nullptr, name + ": " + file.error};
  JsonParsed parsed = parse_json_text(file.text, limits);
  if (!parsed.ok()) parsed.error = name + ": " + parsed.error;
  return parsed;
}

}  // namespace synbench::drivers
