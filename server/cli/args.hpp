// Command-line flags of one subcommand: "--name value", "--name=value" or a bare switch.
// Every problem is a UsageError naming the flag, which the CLI turns into exit status 2.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace synbench::cli {

class UsageError : public std::runtime_error {
 public:
  UsageError(const std::string& flag, const std::string& reason)
      : std::runtime_error(flag + ": " + reason) {}
};

class Args {
 public:
  // `switches` take no value; `valued` take one; `repeatable` take one each time they are
  // given. Anything else is an unknown flag.
  Args(const std::vector<std::string>& argv, std::set<std::string> switches,
       std::set<std::string> valued, std::set<std::string> repeatable = {});

  bool has(const std::string& flag) const;
  std::optional<std::string> text(const std::string& flag) const;
  std::optional<double> number(const std::string& flag) const;
  // Every value of a repeatable flag, in order.
  std::vector<std::string> all(const std::string& flag) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::set<std::string> switches_;
  std::map<std::string, std::string> values_;
  std::map<std::string, std::vector<std::string>> repeated_;
  std::vector<std::string> positional_;
};

}  // namespace synbench::cli
