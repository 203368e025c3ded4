// Printing profile and bench config problems.
#include "server/cli/profile_problems.hpp"

namespace synbench::cli {

std::string problem_text(const std::string& file, const drivers::ProfileError& e) {
  // A file that cannot be read or parsed is already named by the reader's own "FILE: reason".
  if (e.pointer.empty() && e.reason.rfind(file + ":", 0) == 0) return e.reason;
  return file + ": " + (e.pointer.empty() ? "" : e.pointer + ": ") + e.reason;
}

void print_problems(std::ostream& out, const std::string& file, const std::vector<drivers::ProfileError>& errors) {
  for (const auto& e : errors) out << problem_text(file, e) << "\n";
}

std::string unit_ids(const drivers::DeviceProfile& p) {
  std::set<int> ids;
  for (const auto& s : p.signals) ids.insert(s.unit_id);
  std::string text;
  for (const int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text;
}

}  // namespace synbench::cli
