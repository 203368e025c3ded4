// printf-style text for messages. The format is checked against the arguments by the compiler
// at every call (-Wformat=2), which a helper taking the format as a plain pointer defeats.
#pragma once

#include <string>

namespace synbench::drivers {

std::string printf_text(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace synbench::drivers
