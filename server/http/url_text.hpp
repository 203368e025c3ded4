// Text of request targets: percent-decoding of paths and query strings, and ASCII lower case
// for case-insensitive tokens (schemes, escapes). One decoder for the router's parameters and
// the static files' paths, so both read a target alike.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace synbench::http {

// Whether '+' means a space (query strings, form encoding) or itself (paths).
enum class Plus { space, literal };

// Decodes %XX escapes; nullopt when an escape is malformed (a '%' not followed by two hex
// digits). The result may hold any byte, NUL and bytes that are not UTF-8 included: callers
// decide what they accept.
std::optional<std::string> percent_decode(std::string_view s, Plus plus);

std::string ascii_lower(std::string_view s);

}  // namespace synbench::http
