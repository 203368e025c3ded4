// Flag parsing with errors that name the flag.
#include "server/cli/args.hpp"

#include <cmath>
#include <cstdlib>

namespace synbench::cli {

Args::Args(const std::vector<std::string>& argv, std::set<std::string> switches,
           std::set<std::string> valued, std::set<std::string> repeatable) {
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.rfind("--", 0) != 0) {
      positional_.push_back(a);
      continue;
    }
    std::string name = a, value;
    bool inline_value = false;
    if (auto eq = a.find('='); eq != std::string::npos) {
      name = a.substr(0, eq);
      value = a.substr(eq + 1);
      inline_value = true;
    }
    if (switches.count(name)) {
      if (inline_value) throw UsageError(name, "takes no value");
      switches_.insert(name);
    } else if (valued.count(name) || repeatable.count(name)) {
      if (!inline_value) {
        if (i + 1 >= argv.size()) throw UsageError(name, "needs a value");
        value = argv[++i];
      }
      if (repeatable.count(name)) {
        repeated_[name].push_back(value);
        continue;
      }
      if (values_.count(name)) throw UsageError(name, "given twice");
      values_[name] = value;
    } else {
      throw UsageError(name, "unknown flag (see --help)");
    }
  }
}

bool Args::has(const std::string& flag) const { return switches_.count(flag) > 0; }

std::optional<std::string> Args::text(const std::string& flag) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::vector<std::string> Args::all(const std::string& flag) const {
  auto it = repeated_.find(flag);
  return it == repeated_.end() ? std::vector<std::string>{} : it->second;
}

std::optional<double> Args::number(const std::string& flag) const {
  auto t = text(flag);
  if (!t) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(t->c_str(), &end);
  if (t->empty() || end != t->c_str() + t->size() || !std::isfinite(v))
    throw UsageError(flag, "'" + *t + "' is not a number");
  return v;
}

}  // namespace synbench::cli
