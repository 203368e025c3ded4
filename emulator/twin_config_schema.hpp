// The parameter table of the twin: one row per config key, binding the key to its field in
// TwinConfig with its unit, valid range and source. Loading, validation, the default JSON file
// and the documentation are all generated from this one table, so they cannot drift apart.
#pragma once

#include "drivers/json.hpp"


#include <functional>
#include <span>
#include <stdexcept>
#include <string_view>
#include <string>
#include <variant>
#include <vector>

#include "drivers/json_reader.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {

// A config problem: the JSON pointer of the key ("/synrm/rs_ohm"; "" for the document or the
// file) and the reason. what() is "/synrm/rs_ohm: -1 is outside (0, inf]".
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(drivers::JsonError error);
  const std::string& pointer() const { return error_.pointer; }
  const std::string& reason() const { return error_.reason; }

 private:
  drivers::JsonError error_;
};

// A string key with a fixed set of values, bound to an enum field: its names by value, and the
// field read and written as the index into them.
struct ChoiceField {
  std::span<const std::string_view> names;
  std::function<std::size_t()> get;
  std::function<void(std::size_t)> set;
};

struct ParamRow {
  std::string key;  // dotted path, e.g. "synrm.rs_ohm"
  std::variant<double*, int*, bool*, ChoiceField> field;
  double min = 0;   // inclusive bounds for numbers; ignored for bool and choices
  double max = 0;
  bool min_exclusive = false;
  bool assumed = false;              // not in the thesis: our calibration
  std::string source;                // where the default comes from
  std::string doc;                   // what it is
};

// The rows bound to the fields of `config`.
std::vector<ParamRow> param_table(TwinConfig& config);

// Overlays a (possibly partial) JSON document on `config`. Keys starting with '_' are comments.
// Throws ConfigError naming the first bad key by its JSON pointer.
void apply_json(TwinConfig& config, const synbench::Json& doc);

// Reads and applies a JSON file; a parse error names the file, line and column.
TwinConfig load_twin_config_file(const std::string& path);

// Checks relations between keys that single-row ranges cannot express.
void validate(const TwinConfig& config);

// The full config as JSON, with a per-section "_assumed" list of the keys that are our calibration.
synbench::Json to_json(const TwinConfig& config);

// Markdown table of every key: default, range, source, meaning.
std::string markdown_reference(const TwinConfig& config);

}  // namespace synbench::emulator
