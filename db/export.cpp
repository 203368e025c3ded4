// CSV and JSON export of stored points. Both walk bench::to_json's output, so a field added to the
// record appears here without a change.
#include "db/export.hpp"

#include <charconv>
#include <cmath>
#include <string_view>

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

void append_value(std::string& out, const synbench::Json& v) {
  if (v.is_null()) return;
  if (v.is_number_float()) append_number(out, v.get<double>());
  else if (v.is_number_unsigned()) out += std::to_string(v.get<std::uint64_t>());
  else if (v.is_number_integer()) out += std::to_string(v.get<std::int64_t>());
  else if (v.is_boolean()) out += v.get<bool>() ? "true" : "false";
  else if (v.is_string()) append_text(out, v.get_ref<const std::string&>());
  else append_text(out, v.dump());  // nothing in the record today; kept readable if it comes
}

// The truth object's keys, from the record's own JSON form.
synbench::Json truth_template() {
  bench::PointRecord r;
  r.truth = drivers::TruthWindow{};
  return bench::to_json(r)["truth"];
}

}  // namespace

std::vector<std::string> csv_columns() {
  std::vector<std::string> cols{"point_index"};
  bench::PointRecord r;
  r.truth = drivers::TruthWindow{};
  const auto j = bench::to_json(r);  // named: items() only refers to it
  for (const auto& [key, value] : j.items()) {
    if (key != "truth") {
      cols.push_back(key);
      continue;
    }
    for (const auto& [tkey, tvalue] : value.items()) cols.push_back("truth_" + tkey);
  }
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
  const auto truth_keys = truth_template();
  for (const auto& row : rows) {
    out += std::to_string(row.index);
    const auto j = bench::to_json(row.record);
    for (const auto& [key, value] : j.items()) {
      if (key != "truth") {
        out += ',';
        append_value(out, value);
        continue;
      }
      // A null truth still takes its columns, empty, so every line has the header's width.
      for (const auto& [tkey, tvalue] : truth_keys.items()) {
        out += ',';
        if (value.is_object()) append_value(out, value.at(tkey));
      }
    }
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
