// JSON and text forms of a point record: loops over its member table.
#include "bench/point_record.hpp"

#include "bench/point_record_fields.hpp"
#include "drivers/json.hpp"

#include <cstdio>
#include <sstream>

namespace synbench::bench {
namespace {

template <class T>
synbench::Json value_json(const T& v);
template <class T>
synbench::Json value_json(const std::optional<T>& v);

template <class S>
synbench::Json object_json(const S& s) {
  synbench::Json j = synbench::Json::object();
  for_each_field(FieldTable<S>::fields, [&](const auto& f) { j[f.name] = value_json(s.*f.member); });
  return j;
}

template <class T>
synbench::Json value_json(const T& v) {
  if constexpr (TextField<T>) return std::string(field_text(v));
  else if constexpr (HasFieldTable<T>) return object_json(v);
  else return synbench::Json(v);
}

template <class T>
synbench::Json value_json(const std::optional<T>& v) {
  return v ? value_json(*v) : synbench::Json(nullptr);
}

}  // namespace

synbench::Json to_json(const PointRecord& r) { return object_json(r); }
synbench::Json to_json(const drivers::TruthWindow& t) { return object_json(t); }

std::string to_text(const PointRecord& r) {
  std::ostringstream s;
  const auto j = to_json(r);
  auto line = [&](const std::string& key, const synbench::Json& v) {
    char buf[64];
    if (v.is_number_float()) {
      std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
    } else if (v.is_null()) {
      std::snprintf(buf, sizeof buf, "-");
    } else {
      std::snprintf(buf, sizeof buf, "%s", v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
    }
    s << "  " << key << std::string(key.size() < 18 ? 18 - key.size() : 1, ' ') << buf << "\n";
  };
  for (const auto& [key, v] : j.items())
    if (key != "truth") line(key, v);
  if (r.truth) {
    s << "  truth (plant's own values)\n";
    for (const auto& [key, v] : j["truth"].items()) line("  " + key, v);
  }
  return s.str();
}

}  // namespace synbench::bench
