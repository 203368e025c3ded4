// UTF-8 checks for text that goes into JSON. nlohmann's dump() throws on a string that is not
// UTF-8, and request paths, query parameters, file contents and parser messages can carry any
// byte: these find the first bad byte (for a 400 naming it) and make any text printable.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace synbench::drivers {

// Offset of the first byte that does not belong to a well-formed UTF-8 sequence (RFC 3629: no
// overlong forms, no surrogates, nothing above U+10FFFF), or nullopt when all of `text` is UTF-8.
std::optional<std::size_t> first_invalid_utf8(std::string_view text);

inline bool is_valid_utf8(std::string_view text) { return !first_invalid_utf8(text); }

// `text` with every byte outside a well-formed sequence written as "\xNN": valid UTF-8 that
// still shows what was sent (for messages and logs).
std::string escape_invalid_utf8(std::string_view text);

}  // namespace synbench::drivers
