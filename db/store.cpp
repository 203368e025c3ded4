// db::Store: picks the backend from the target (a file path or a PostgreSQL URL) and forwards
// each call to it; the timestamps both backends write; the redaction of a URL's password.
#include "db/store.hpp"

#include <chrono>
#include <ctime>
#include <regex>
#include <stdexcept>

#include "db/backend.hpp"

namespace synbench::db {

std::string now_utc() {
  using namespace std::chrono;
  const auto now = system_clock::now();
  const auto ms = duration_cast<milliseconds>(now.time_since_epoch()).count() % 1000;
  const std::time_t t = system_clock::to_time_t(now);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[40];
  std::snprintf(out, sizeof out, "%s.%03dZ", buf, static_cast<int>(ms));
  return out;
}

bool is_postgres_target(std::string_view target) {
  if (target.starts_with("postgresql://") || target.starts_with("postgres://")) return true;
  // libpq's key=value form ("host=/run/pg dbname=lab"): its first word is a keyword and '='.
  static const std::regex conninfo(R"(^\s*[a-z_]+\s*=.*)");
  return std::regex_match(std::string(target), conninfo);
}

std::string shown_target(std::string_view target) {
  if (!is_postgres_target(target)) return std::string(target);
  std::string s(target);
  // URL: scheme://user:PASSWORD@host..., and ?password=... among its parameters.
  if (const auto scheme = s.find("://"); scheme != std::string::npos) {
    const auto rest = scheme + 3;
    const auto at = s.find('@', rest);
    const auto slash = s.find('/', rest);
    if (at != std::string::npos && (slash == std::string::npos || at < slash)) {
      const auto colon = s.find(':', rest);
      if (colon != std::string::npos && colon < at) s.replace(colon + 1, at - colon - 1, "***");
    }
  }
  static const std::regex password(R"((password\s*=\s*)('([^'\\]|\\.)*'|[^&\s]*))", std::regex::icase);
  return std::regex_replace(s, password, "$1***");
}

Result<Store> Store::open(const std::filesystem::path& target, const StoreOptions& options) {
  const std::string t = target.string();
  if (is_postgres_target(t)) {
    const std::string shown = shown_target(t);
    auto b = detail::open_postgres(t, shown, options);
    if (!b) return b.error();
    return Store(std::move(*b), shown, Kind::postgres);
  }
  auto b = detail::open_sqlite(target, options);
  if (!b) return b.error();
  return Store(std::move(*b), t, Kind::sqlite);
}

Store::Store(std::unique_ptr<detail::Backend> b, std::string shown, Kind kind)
    : backend_(std::move(b)), path_(std::move(shown)), kind_(kind) {}
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;
Store::~Store() = default;

detail::Backend& Store::impl() const {
  if (!backend_) throw std::logic_error("db::Store used after being moved from");
  return *backend_;
}

const std::filesystem::path& Store::path() const {
  (void)impl();
  return path_;
}

Result<std::int64_t> Store::create_sweep(const SweepMeta& meta) { return impl().create_sweep(meta); }
Result<std::optional<Sweep>> Store::find_sweep_by_key(std::string_view key) { return impl().find_sweep_by_key(key); }
Status Store::set_sweep_state(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                              bool sparse_plan) {
  return impl().set_sweep_state(sweep_id, state, error, sparse_plan);
}
Result<Sweep> Store::get_sweep(std::int64_t sweep_id) { return impl().get_sweep(sweep_id); }
Result<std::vector<Sweep>> Store::list_sweeps() { return impl().list_sweeps(); }
Result<std::vector<LeftRunning>> Store::abort_left_running() { return impl().abort_left_running(); }
Status Store::insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record) {
  return impl().insert_point(sweep_id, point_index, record);
}
Result<std::vector<PointRow>> Store::points(std::int64_t sweep_id) { return impl().points(sweep_id); }
Result<std::vector<std::int64_t>> Store::missing_indices(std::int64_t sweep_id) {
  return impl().missing_indices(sweep_id);
}
Result<std::optional<std::int64_t>> Store::first_missing_index(std::int64_t sweep_id) {
  auto m = missing_indices(sweep_id);
  if (!m) return m.error();
  if (m->empty()) return std::optional<std::int64_t>();
  return std::optional<std::int64_t>(m->front());
}
Result<std::int64_t> Store::add_event(std::optional<std::int64_t> sweep_id, EventKind kind, std::string_view message) {
  return impl().add_event(sweep_id, kind, message);
}
Result<std::vector<Event>> Store::events(std::optional<std::int64_t> sweep_id) { return impl().events(sweep_id); }
Status Store::integrity_check() { return impl().integrity_check(); }
Result<std::string> Store::pragma(std::string_view name) { return impl().pragma(name); }

}  // namespace synbench::db
