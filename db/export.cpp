// CSV and JSON export of stored points. CSV walks the record's member table, JSON bench::to_json
// (itself the table), so a field added to the record appears here without a change.
#include "db/export.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <type_traits>

#include "bench/point_record_fields.hpp"

namespace synbench::db {
namespace {

void append_number(std::string& out, double v) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char buf[64];
  // Shortest representation that parses back to the same double ("inf" and "-inf" included).
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

void append_text(std::string& out, std::string_view s) {
  if (s.find_first_of(",\"\r\n") == std::string_view::npos) {
    out += s;
    return;
  }
  out += '"';
  for (const char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
}

using bench::HasFieldTable;

// One CSV cell per field, a field with a table of its own (truth) as one per field of that table.
template <class T>
constexpr std::size_t cell_count() {
  if constexpr (HasFieldTable<T>) return std::tuple_size_v<std::remove_cvref_t<decltype(bench::FieldTable<T>::fields)>>;
  else return 1;
}

template <class S>
void append_header(std::vector<std::string>& cols, const std::string& prefix) {
  bench::for_each_field(bench::FieldTable<S>::fields, [&](const auto& f) {
    using T = bench::held_t<typename std::decay_t<decltype(f)>::value_type>;
    if constexpr (HasFieldTable<T>) append_header<T>(cols, prefix + std::string(f.name) + "_");
    else cols.push_back(prefix + std::string(f.name));
  });
}

template <class T>
void append_cells(std::string& out, const std::optional<T>& v);

// Appends ",cell" for each of the value's cells.
template <class T>
void append_cells(std::string& out, const T& v) {
  if constexpr (HasFieldTable<T>) {
    bench::for_each_field(bench::FieldTable<T>::fields, [&](const auto& f) { append_cells(out, v.*f.member); });
  } else {
    out += ',';
    if constexpr (std::is_same_v<T, double>) append_number(out, v);
    else if constexpr (std::is_same_v<T, bool>) out += v ? "true" : "false";
    else if constexpr (std::is_integral_v<T>) out += std::to_string(v);
    else if constexpr (bench::TextField<T>) append_text(out, bench::field_text(v));
    else append_text(out, v);
  }
}

// An empty optional leaves its cells empty, so every line has the header's width.
template <class T>
void append_cells(std::string& out, const std::optional<T>& v) {
  if (v) append_cells(out, *v);
  else out.append(cell_count<T>(), ',');
}

}  // namespace

std::vector<std::string> csv_columns() {
  std::vector<std::string> cols{"point_index"};
  append_header<bench::PointRecord>(cols, "");
  return cols;
}

std::string points_to_csv(std::span<const PointRow> rows) {
  std::string out;
  const auto cols = csv_columns();
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (i) out += ',';
    out += cols[i];
  }
  out += '\n';
  for (const auto& row : rows) {
    out += std::to_string(row.index);
    append_cells(out, row.record);
    out += '\n';
  }
  return out;
}

synbench::Json points_to_json(std::span<const PointRow> rows) {
  synbench::Json out = synbench::Json::array();
  for (const auto& row : rows) {
    synbench::Json j = synbench::Json::object();
    j["point_index"] = row.index;
    const auto record = bench::to_json(row.record);
    for (const auto& [key, value] : record.items()) j[key] = value;
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace synbench::db
