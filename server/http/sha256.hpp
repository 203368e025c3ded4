// SHA-256 (FIPS 180-4), so the tokens file stores digests, never tokens, without pulling in a
// crypto library for one hash.
#pragma once

#include <string>
#include <string_view>

namespace synbench::http {

// Lower-case hex digest of `data`.
std::string sha256_hex(std::string_view data);

}  // namespace synbench::http
