// Decimal text of a double that reads back to the same value, for messages and the generated
// register map (whose text must not depend on stream state or locale). Plain notation where a
// reader expects it (600000, not 6e+05); exponents only for the very large or small.
#pragma once

#include <charconv>
#include <cmath>
#include <string>

namespace synbench::drivers {

inline std::string format_number(double v) {
  char buf[64];
  const double mag = std::abs(v);
  const bool plain = v == 0 || (mag >= 1e-6 && mag < 1e15);
  const auto r = plain ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
                       : std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace synbench::drivers
