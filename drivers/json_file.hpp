// The one reader of JSON input, for every loader (twin config, bench config, device profile,
// sweep plan, the daemon's config and tokens files) and for request bodies. It never throws on
// any input: a path that is not a regular file (a directory, a device, a FIFO), a file over the
// size cap, bytes that are not UTF-8, nesting deeper than the depth cap (the parsed tree is
// walked recursively by nlohmann's copy and dump, and by our validators), and anything
// nlohmann refuses, number overflow (1e309, a 400-digit integer) included, come back as a
// reason. In drivers/, the lowest layer, so every layer above can use it.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "drivers/json.hpp"

namespace synbench::drivers {

struct JsonLimits {
  std::size_t max_bytes = 16u << 20;  // a config file is kilobytes; this only stops a runaway
  std::size_t max_depth = 64;         // our documents nest 6 levels at most
};

struct JsonParsed {
  synbench::Json doc;  // null when `error` is set
  // Empty on success. For parse_json_text the reason alone ("not valid UTF-8 at byte 12"), to
  // follow a subject ("the body is ..."); for read_json_file "PATH: reason".
  std::string error;
  bool ok() const { return error.empty(); }
};

// Parses `text` as one JSON document. Reasons: "not valid UTF-8 at byte N", "nested deeper than
// N levels at byte N", "not valid JSON: <the parser's message>" (valid UTF-8 in every case).
JsonParsed parse_json_text(std::string_view text, const JsonLimits& limits = {});

// Reads a regular file (at most limits.max_bytes) and parses it. Reasons add "cannot open: ...",
// "cannot read: ...", "a directory, not a regular file", "larger than 16 MiB", ...
JsonParsed read_json_file(const std::filesystem::path& path, const JsonLimits& limits = {});

struct TextRead {
  std::string text;
  std::string error;  // the reason alone; empty on success
};
// The file-reading half of read_json_file: the same refusals, for callers with their own parser.
TextRead read_text_file(const std::filesystem::path& path, std::size_t max_bytes);

}  // namespace synbench::drivers
