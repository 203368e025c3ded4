// Shortest decimal text of a double that reads back to the same value, for messages and the
// generated register map (whose text must not depend on stream state or locale).
#pragma once

#include <charconv>
#include <string>

namespace synbench::drivers {

inline std::string format_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace synbench::drivers
