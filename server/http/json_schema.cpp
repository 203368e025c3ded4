// The JSON Schema subset's validator and its schema check; see json_schema.hpp.
#include "server/http/json_schema.hpp"

#include <cmath>
#include <set>

#include "drivers/json.hpp"
#include "drivers/json_reader.hpp"
#include "drivers/profile/number_format.hpp"

namespace synbench::http {

std::string to_string(const SchemaError& e) {
  return (e.pointer.empty() ? std::string("(document)") : e.pointer) + ": " + e.reason;
}

std::string to_string(const std::vector<SchemaError>& errors) {
  std::string out;
  for (const auto& e : errors) out += (out.empty() ? "" : "; ") + to_string(e);
  return out;
}

namespace {

using Errors = std::vector<SchemaError>;

std::string member(const std::string& ptr, const std::string& key) { return ptr + "/" + drivers::json_pointer_token(key); }

bool is_type(const synbench::Json& v, const std::string& type) {
  if (type == "object") return v.is_object();
  if (type == "array") return v.is_array();
  if (type == "string") return v.is_string();
  if (type == "boolean") return v.is_boolean();
  if (type == "number") return v.is_number();
  // 3.0: an integer is a number without a fraction, however it is written (2.0 included).
  if (type == "integer")
    return v.is_number_integer() || (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>());
  return false;
}

std::string type_text(const std::string& type) {
  if (type == "object") return "an object";
  if (type == "array") return "an array";
  if (type == "string") return "a string";
  if (type == "boolean") return "true or false";
  if (type == "integer") return "an integer";
  return "a number";
}

// A value as a message shows it: a string as it is, anything else as JSON.
std::string shown(const synbench::Json& v) {
  if (v.is_string()) return "'" + v.get<std::string>() + "'";
  if (v.is_number()) return drivers::format_number(v.get<double>());
  return v.dump(-1, ' ', false, synbench::Json::error_handler_t::replace);
}

std::size_t code_points(const std::string& s) {
  std::size_t n = 0;
  for (const unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

void check_bounds(const synbench::Json& schema, double x, const std::string& ptr, Errors& out) {
  const bool has_min = schema.contains("minimum"), has_max = schema.contains("maximum");
  const bool open_min = schema.value("exclusiveMinimum", false), open_max = schema.value("exclusiveMaximum", false);
  const double lo = has_min ? schema["minimum"].get<double>() : 0, hi = has_max ? schema["maximum"].get<double>() : 0;
  const bool ok = (!has_min || (open_min ? x > lo : x >= lo)) && (!has_max || (open_max ? x < hi : x <= hi));
  if (ok) return;
  const std::string n = drivers::format_number(x);
  if (has_min && has_max)
    out.push_back({ptr, n + " is outside " + (open_min ? "(" : "[") + drivers::format_number(lo) + ", " +
                            drivers::format_number(hi) + (open_max ? ")" : "]")});
  else if (has_min)
    out.push_back({ptr, n + " must be " + (open_min ? "above " : "at least ") + drivers::format_number(lo)});
  else
    out.push_back({ptr, n + " must be " + (open_max ? "below " : "at most ") + drivers::format_number(hi)});
}

void check_object(const synbench::Json& schema, const synbench::Json& v, const std::string& ptr, Errors& out);

void validate_at(const synbench::Json& schema, const synbench::Json& v, const std::string& ptr, Errors& out) {
  if (v.is_null() && schema.value("nullable", false)) return;
  if (const auto t = schema.find("type"); t != schema.end() && !is_type(v, t->get<std::string>())) {
    out.push_back({ptr, "must be " + type_text(t->get<std::string>()) + (schema.value("nullable", false) ? " or null" : "")});
    return;  // the other keywords would only repeat it
  }
  if (const auto e = schema.find("enum"); e != schema.end()) {
    bool found = false;
    std::string list;
    for (const auto& option : *e) {
      found = found || option == v;
      list += (list.empty() ? "" : ", ") + (option.is_string() ? option.get<std::string>() : shown(option));
    }
    if (!found) out.push_back({ptr, "must be one of " + list + " (got " + shown(v) + ")"});
  }
  if (v.is_number()) check_bounds(schema, v.get<double>(), ptr, out);
  if (v.is_string()) {
    const std::size_t n = code_points(v.get<std::string>());
    if (schema.contains("minLength") && n < schema["minLength"].get<std::size_t>())
      out.push_back({ptr, "must be at least " + std::to_string(schema["minLength"].get<std::size_t>()) + " characters long"});
    if (schema.contains("maxLength") && n > schema["maxLength"].get<std::size_t>())
      out.push_back({ptr, "must be at most " + std::to_string(schema["maxLength"].get<std::size_t>()) + " characters long"});
  }
  if (v.is_array()) {
    if (schema.contains("minItems") && v.size() < schema["minItems"].get<std::size_t>())
      out.push_back({ptr, "must have at least " + std::to_string(schema["minItems"].get<std::size_t>()) + " items"});
    if (schema.contains("maxItems") && v.size() > schema["maxItems"].get<std::size_t>())
      out.push_back({ptr, "must have at most " + std::to_string(schema["maxItems"].get<std::size_t>()) + " items"});
    if (const auto items = schema.find("items"); items != schema.end())
      for (std::size_t i = 0; i < v.size(); ++i) validate_at(*items, v[i], ptr + "/" + std::to_string(i), out);
  }
  if (v.is_object()) check_object(schema, v, ptr, out);
  if (const auto one_of = schema.find("oneOf"); one_of != schema.end()) {
    std::size_t matches = 0;
    std::string why;
    for (const auto& alternative : *one_of) {
      Errors errors;
      validate_at(alternative, v, ptr, errors);
      if (errors.empty()) {
        ++matches;
        continue;
      }
      // "must be a string or an object"
      std::string reason = errors.front().reason;
      if (!why.empty() && reason.rfind("must be ", 0) == 0) reason.erase(0, 8);
      why += (why.empty() ? "" : " or ") + reason;
    }
    if (matches == 0) out.push_back({ptr, why});
    else if (matches > 1) out.push_back({ptr, "matches " + std::to_string(matches) + " of its forms where one is allowed"});
  }
}

void check_object(const synbench::Json& schema, const synbench::Json& v, const std::string& ptr, Errors& out) {
  if (const auto required = schema.find("required"); required != schema.end())
    for (const auto& name : *required)
      if (!v.contains(name.get<std::string>())) out.push_back({member(ptr, name.get<std::string>()), "required field is missing"});
  const auto properties = schema.find("properties");
  if (schema.contains("minProperties") && v.size() < schema["minProperties"].get<std::size_t>()) {
    std::string names;
    if (properties != schema.end())
      for (const auto& [name, _] : properties->items()) names += (names.empty() ? "" : ", ") + name;
    out.push_back({ptr, "give at least " + std::to_string(schema["minProperties"].get<std::size_t>()) + " of " + names});
  }
  const auto additional = schema.find("additionalProperties");
  for (const auto& [name, value] : v.items()) {
    if (properties != schema.end() && properties->contains(name)) {
      validate_at((*properties)[name], value, member(ptr, name), out);
    } else if (additional != schema.end() && additional->is_boolean()) {
      if (additional->get<bool>()) continue;
      std::string known;
      if (properties != schema.end())
        for (const auto& [k, _] : properties->items()) known += (known.empty() ? "" : ", ") + k;
      out.push_back({member(ptr, name), "unknown field (expected: " + known + ")"});
    } else if (additional != schema.end()) {
      validate_at(*additional, value, member(ptr, name), out);
    }
  }
}

bool whole(const synbench::Json& v) { return v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0); }

void check_schema_at(const synbench::Json& schema, const std::string& ptr, Errors& out) {
  if (!schema.is_object()) {
    out.push_back({ptr, "a schema must be an object"});
    return;
  }
  static const std::set<std::string> kTypes = {"object", "array", "string", "number", "integer", "boolean"};
  for (const auto& [key, v] : schema.items()) {
    const std::string at = member(ptr, key);
    const auto expect = [&](bool ok, const char* what) {
      if (!ok) out.push_back({at, std::string("must be ") + what});
    };
    if (key == "type") expect(v.is_string() && kTypes.count(v.get<std::string>()), "one of object, array, string, number, integer, boolean");
    else if (key == "nullable" || key == "exclusiveMinimum" || key == "exclusiveMaximum") expect(v.is_boolean(), "true or false");
    else if (key == "description") expect(v.is_string(), "a string");
    else if (key == "minimum" || key == "maximum") expect(v.is_number(), "a number");
    else if (key == "minProperties" || key == "minItems" || key == "maxItems" || key == "minLength" || key == "maxLength")
      expect(whole(v), "a whole number");
    else if (key == "enum") expect(v.is_array() && !v.empty(), "a non-empty array");
    else if (key == "required") {
      bool ok = v.is_array();
      for (const auto& n : v) ok = ok && n.is_string();
      expect(ok, "an array of strings");
    } else if (key == "properties") {
      if (!v.is_object()) expect(false, "an object");
      else
        for (const auto& [name, sub] : v.items()) check_schema_at(sub, member(at, name), out);
    } else if (key == "additionalProperties") {
      if (!v.is_boolean()) check_schema_at(v, at, out);
    } else if (key == "items") {
      check_schema_at(v, at, out);
    } else if (key == "oneOf") {
      if (!v.is_array() || v.empty()) expect(false, "a non-empty array of schemas");
      else
        for (std::size_t i = 0; i < v.size(); ++i) check_schema_at(v[i], at + "/" + std::to_string(i), out);
    } else {
      out.push_back({at, "keyword not implemented by the validator (it would be published but not checked)"});
    }
  }
  // 3.0's exclusive bounds are flags on minimum/maximum: alone they mean nothing.
  if (schema.contains("exclusiveMinimum") && !schema.contains("minimum"))
    out.push_back({member(ptr, "exclusiveMinimum"), "needs minimum"});
  if (schema.contains("exclusiveMaximum") && !schema.contains("maximum"))
    out.push_back({member(ptr, "exclusiveMaximum"), "needs maximum"});
}

}  // namespace

std::vector<SchemaError> validate(const synbench::Json& schema, const synbench::Json& value) {
  Errors out;
  validate_at(schema, value, "", out);
  return out;
}

std::vector<SchemaError> check_schema(const synbench::Json& schema) {
  Errors out;
  check_schema_at(schema, "", out);
  return out;
}

}  // namespace synbench::http
