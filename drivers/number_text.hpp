// A number as messages and logs print it: iostream's default, six significant digits, no
// trailing zeros ("3000", "0.25", "1e+06"). One spelling for every layer's messages.
#pragma once

#include <sstream>
#include <string>

namespace synbench::drivers {

inline std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace synbench::drivers
