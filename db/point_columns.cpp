// A point record's columns: binding and reading, one overload per type of field.
#include "db/point_columns.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <utility>

#include "db/pg.hpp"
#include "db/sqlite.hpp"
#include "drivers/json.hpp"

namespace synbench::db::detail {
namespace {

using bench::HasFieldTable;
using bench::TextField;

template <class T>
constexpr bool kNested = HasFieldTable<bench::held_t<T>>;

// --- binding ---

template <class St, class T>
void bind_value(St& st, int i, const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    if (std::isnan(v)) st.bind_null(i);
    else st.bind(i, v);
  } else if constexpr (std::is_same_v<T, bool>) {
    st.bind(i, std::int64_t{v ? 1 : 0});
  } else if constexpr (std::is_integral_v<T>) {
    st.bind(i, static_cast<std::int64_t>(v));
  } else if constexpr (TextField<T>) {
    st.bind(i, bench::field_text(v));
  } else if constexpr (std::is_same_v<T, std::string>) {
    st.bind(i, std::string_view(v));
  } else {
    static_assert(HasFieldTable<T>, "a record field of a type the database has no column form for");
    st.bind(i, bench::to_json(v).dump());  // shortest round-trip doubles: they read back bit for bit
  }
}

template <class St, class T>
void bind_value(St& st, int i, const std::optional<T>& v) {
  if (v) bind_value(st, i, *v);
  else st.bind_null(i);
}

// --- reading ---

Error bad(std::string_view column, const std::string& why) {
  return make_error(errc::bad_record, std::string(column) + " " + why);
}

// A nested table's fields from the JSON object its column holds. JSON has no NaN or infinity;
// nlohmann writes them as null, which comes back as NaN.
template <class S>
Status read_object(const std::string& text, std::string_view column, S& s) {
  const auto j = synbench::Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return bad(column, "is not a JSON object");
  Status status;
  bench::for_each_field(bench::FieldTable<S>::fields, [&](const auto& f) {
    static_assert(std::is_same_v<typename std::decay_t<decltype(f)>::value_type, double>,
                  "a nested table's fields are numbers in its JSON column");
    if (!status) return;
    const std::string key(f.name);
    const auto it = j.find(key);
    if (it == j.end()) status = bad(column, "has no " + key);
    else if (it->is_null()) s.*f.member = std::numeric_limits<double>::quiet_NaN();
    else if (it->is_number()) s.*f.member = it->template get<double>();
    else status = make_error(errc::bad_record, std::string(column) + "." + key + " is not a number");
  });
  return status;
}

template <class Row, class T>
Status read_value(const Row& st, int i, std::string_view column, T& v) {
  if constexpr (std::is_same_v<T, double>) {
    v = st.is_null(i) ? std::numeric_limits<double>::quiet_NaN() : st.real(i);
  } else if constexpr (std::is_same_v<T, bool>) {
    v = st.integer(i) != 0;
  } else if constexpr (std::is_integral_v<T>) {
    const std::int64_t x = st.integer(i);
    if (!std::in_range<T>(x)) return bad(column, "out of range");
    v = static_cast<T>(x);
  } else if constexpr (TextField<T>) {
    const std::string text = st.text(i);
    const auto parsed = bench::parse_field_text(text, static_cast<T*>(nullptr));
    if (!parsed) return make_error(errc::bad_record, "unknown " + std::string(column) + " \"" + text + "\"");
    v = *parsed;
  } else if constexpr (std::is_same_v<T, std::string>) {
    v = st.text(i);
  } else {
    static_assert(HasFieldTable<T>, "a record field of a type the database has no column form for");
    return read_object(st.text(i), column, v);
  }
  return {};
}

template <class Row, class T>
Status read_value(const Row& st, int i, std::string_view column, std::optional<T>& v) {
  if (st.is_null(i)) {
    v.reset();
    return {};
  }
  T x{};
  if (auto s = read_value(st, i, column, x); !s) return s;
  v = std::move(x);
  return {};
}

}  // namespace

const std::vector<std::string>& record_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> out;
    bench::for_each_field(bench::kPointRecordFields, [&](const auto& f) {
      using T = typename std::decay_t<decltype(f)>::value_type;
      out.push_back(std::string(f.name) + (kNested<T> ? "_json" : ""));
    });
    return out;
  }();
  return columns;
}

template <class Params>
void bind_record(Params& st, int first, const bench::PointRecord& r) {
  int i = first;
  bench::for_each_field(bench::kPointRecordFields, [&](const auto& f) { bind_value(st, i++, r.*f.member); });
}

template <class Row>
Status read_record(const Row& st, int first, bench::PointRecord& r) {
  const auto& columns = record_columns();
  Status status;
  int k = 0;
  bench::for_each_field(bench::kPointRecordFields, [&](const auto& f) {
    if (status) status = read_value(st, first + k, columns[static_cast<std::size_t>(k)], r.*f.member);
    ++k;
  });
  return status;
}

template void bind_record(Statement&, int, const bench::PointRecord&);
template void bind_record(PgParams&, int, const bench::PointRecord&);
template Status read_record(const Statement&, int, bench::PointRecord&);
template Status read_record(const PgRow&, int, bench::PointRecord&);

}  // namespace synbench::db::detail
