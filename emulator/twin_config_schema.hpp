// The parameter table of the twin: one row per config key, binding the key to its field in
// TwinConfig with its unit, valid range and source. Loading, validation, the default JSON file
// and the documentation are all generated from this one table, so they cannot drift apart.
#pragma once

#include "drivers/json.hpp"


#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "emulator/twin_config.hpp"

namespace synbench::emulator {

// A config problem, naming the key (dotted JSON path) and the reason.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string key, std::string reason);
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string key_;
  std::string reason_;
};

struct ParamRow {
  std::string key;  // dotted path, e.g. "synrm.rs_ohm"
  std::variant<double*, int*, bool*, std::string*> field;
  double min = 0;   // inclusive bounds for numbers; ignored for bool and string
  double max = 0;
  bool min_exclusive = false;
  std::vector<std::string> choices;  // allowed values of a string
  bool assumed = false;              // not in the thesis: our calibration
  std::string source;                // where the default comes from
  std::string doc;                   // what it is
};

// The rows bound to the fields of `config`.
std::vector<ParamRow> param_table(TwinConfig& config);

// Overlays a (possibly partial) JSON document on `config`. Keys starting with '_' are comments.
// Throws ConfigError naming the first bad key.
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
