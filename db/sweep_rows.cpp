// The backends' shared SQL and sweep rules.
#include "db/sweep_rows.hpp"

#include <cctype>

namespace synbench::db::detail {

std::string pg_sql(std::string_view sql) {
  std::string out;
  int counter = 0;
  for (std::size_t i = 0; i < sql.size(); ++i) {
    if (sql[i] != '?') {
      out += sql[i];
      continue;
    }
    std::size_t j = i + 1;
    while (j < sql.size() && std::isdigit(static_cast<unsigned char>(sql[j]))) ++j;
    out += '$';
    out += j > i + 1 ? std::string(sql.substr(i + 1, j - i - 1)) : std::to_string(++counter);
    i = j - 1;
  }
  return out;
}

namespace {
std::string record_column_list() {
  std::string s;
  for (const auto& c : record_columns()) s += (s.empty() ? "" : ", ") + c;
  return s;
}
}  // namespace

std::string insert_point_sql() {
  std::string sql = "INSERT INTO points (sweep_id, point_index, " + record_column_list() + ", measured_at) VALUES (?, ?";
  for (int i = 0; i < kRecordColumnCount + 1; ++i) sql += ", ?";
  return sql + ")";
}

std::string select_points_sql() {
  return "SELECT point_index, " + record_column_list() + " FROM points WHERE sweep_id = ? ORDER BY point_index";
}

std::optional<Error> refuse_meta(const SweepMeta& meta) {
  if (meta.name.empty()) return make_error(errc::invalid_argument, "a sweep needs a name");
  if (meta.total_points < 0) return make_error(errc::invalid_argument, "total_points must be >= 0");
  if (meta.key && meta.key->empty()) return make_error(errc::invalid_argument, "a sweep's key, when set, is not empty");
  return std::nullopt;
}

Error duplicate_key(const std::string& key) {
  return make_error(errc::duplicate_key, "a sweep with key \"" + key + "\" is already stored");
}

bool finished(SweepState s) {
  return s == SweepState::completed || s == SweepState::aborted || s == SweepState::faulted;
}

std::optional<Error> refuse_transition(SweepState from, SweepState state, std::int64_t stored, std::int64_t total,
                                       bool sparse_plan) {
  const std::string transition = std::string(name(from)) + " -> " + std::string(name(state));
  if (from == SweepState::completed && state != SweepState::completed)
    return make_error(errc::invalid_transition, transition + ": a completed sweep is final");
  if (state == SweepState::created && from != SweepState::created)
    return make_error(errc::invalid_transition, transition + ": a sweep cannot return to created");
  if (state == SweepState::completed && stored < total && !sparse_plan)
    return make_error(errc::invalid_transition,
                      transition + ": only " + std::to_string(stored) + " of " + std::to_string(total) + " points are stored");
  return std::nullopt;
}

std::vector<std::int64_t> missing_from(std::int64_t total, const std::vector<std::int64_t>& stored) {
  std::vector<std::int64_t> missing;
  std::int64_t next = 0;
  for (const std::int64_t s : stored) {
    for (; next < s && next < total; ++next) missing.push_back(next);
    next = s + 1;
  }
  for (; next < total; ++next) missing.push_back(next);
  return missing;
}

}  // namespace synbench::db::detail
