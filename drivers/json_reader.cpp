// The JSON reader's cursor and its checks; see json_reader.hpp.
#include "drivers/json_reader.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/json.hpp"

namespace synbench::drivers {

std::string to_string(const JsonError& e) {
  return (e.pointer.empty() ? std::string("(document)") : e.pointer) + ": " + e.reason;
}

std::string json_pointer_token(std::string_view key) {
  std::string out;
  for (const char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

bool is_comment_key(std::string_view key) { return !key.empty() && key.front() == '_'; }

NumberCheck positive() {
  return [](double v) { return v > 0 ? std::string() : "must be > 0"; };
}
NumberCheck non_negative() {
  return [](double v) { return v >= 0 ? std::string() : "must be >= 0"; };
}
NumberCheck in_range(double lo, double hi, bool whole) {
  return [=](double v) {
    if (whole && v != std::floor(v)) return std::string("must be a whole number");
    if (v < lo || v > hi)
      return format_number(v) + " is outside [" + format_number(lo) + ", " + format_number(hi) + "]";
    return std::string();
  };
}

bool JsonNode::is_null() const { return value_ && value_->is_null(); }

JsonNode JsonNode::operator[](std::string_view key) const {
  std::string p = pointer_ + "/" + json_pointer_token(key);
  if (!value_ || !value_->is_object()) return JsonNode(nullptr, std::move(p), *reader_);
  const auto it = value_->find(key);
  return JsonNode(it == value_->end() ? nullptr : &*it, std::move(p), *reader_);
}

JsonNode JsonNode::at(std::size_t index) const {
  std::string p = pointer_ + "/" + std::to_string(index);
  if (!value_ || !value_->is_array() || index >= value_->size()) return JsonNode(nullptr, std::move(p), *reader_);
  return JsonNode(&(*value_)[index], std::move(p), *reader_);
}

const JsonNode& JsonNode::required(std::string_view reason) const {
  if (!value_) fail(std::string(reason));
  return *this;
}

bool JsonNode::object(std::string_view reason) const {
  if (!value_) return false;
  if (value_->is_object()) return true;
  fail(std::string(reason));
  return false;
}

void JsonNode::reject_unknown(std::initializer_list<std::string_view> known) const {
  reject_unknown(std::span<const std::string_view>(known.begin(), known.size()));
}

void JsonNode::reject_unknown(std::span<const std::string_view> known) const {
  if (!value_ || !value_->is_object()) return;
  for (const auto& [key, v] : value_->items()) {
    if (is_comment_key(key)) continue;
    if (std::find(known.begin(), known.end(), key) == known.end())
      reader_->fail(pointer_ + "/" + json_pointer_token(key), "unknown field");
  }
}

std::vector<std::pair<std::string, JsonNode>> JsonNode::members() const {
  std::vector<std::pair<std::string, JsonNode>> out;
  if (!value_ || !value_->is_object()) return out;
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    if (is_comment_key(it.key())) continue;
    out.emplace_back(it.key(), JsonNode(&it.value(), pointer_ + "/" + json_pointer_token(it.key()), *reader_));
  }
  return out;
}

std::optional<std::vector<JsonNode>> JsonNode::list(std::string_view reason, bool non_empty) const {
  if (!value_) return std::nullopt;
  if (!value_->is_array()) {
    fail(std::string(reason));
    return std::nullopt;
  }
  if (non_empty && value_->empty()) {
    fail("must not be empty");
    return std::nullopt;
  }
  std::vector<JsonNode> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i) out.push_back(at(i));
  return out;
}

std::optional<double> JsonNode::number(const NumberCheck& check) const {
  if (!value_) return std::nullopt;
  if (!value_->is_number() || !std::isfinite(value_->get<double>())) {
    fail("must be a finite number");
    return std::nullopt;
  }
  const double x = value_->get<double>();
  if (check) {
    if (auto reason = check(x); !reason.empty()) {
      fail(std::move(reason));
      return std::nullopt;
    }
  }
  return x;
}

std::optional<std::int64_t> JsonNode::integer(std::int64_t lo, std::int64_t hi) const {
  if (!value_) return std::nullopt;
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  if (!value_->is_number_integer()) {
    fail("must be an integer in " + range);
    return std::nullopt;
  }
  // Unsigned JSON integers above int64 would wrap on get<int64_t>; they are out of range anyway.
  if (value_->is_number_unsigned() && value_->get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
    fail(std::to_string(value_->get<std::uint64_t>()) + " is outside " + range);
    return std::nullopt;
  }
  const auto v = value_->get<std::int64_t>();
  if (v < lo || v > hi) {
    fail(std::to_string(v) + " is outside " + range);
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> JsonNode::text(bool non_empty) const {
  if (!value_) return std::nullopt;
  if (!value_->is_string() || (non_empty && value_->get_ref<const std::string&>().empty())) {
    fail(non_empty ? "must be a non-empty string" : "must be a string");
    return std::nullopt;
  }
  return value_->get<std::string>();
}

std::optional<bool> JsonNode::boolean() const {
  if (!value_) return std::nullopt;
  if (!value_->is_boolean()) {
    fail("must be true or false");
    return std::nullopt;
  }
  return value_->get<bool>();
}

std::optional<std::vector<std::string>> JsonNode::texts() const {
  if (!value_) return std::nullopt;
  const bool ok = value_->is_array() && std::all_of(value_->begin(), value_->end(),
                                                    [](const synbench::Json& v) { return v.is_string(); });
  if (!ok) {
    fail("must be a list of strings");
    return std::nullopt;
  }
  return value_->get<std::vector<std::string>>();
}

std::string JsonNode::names_list(std::span<const std::string_view> names) {
  std::string s;
  for (const auto n : names) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

std::string JsonNode::unknown_choice(std::string_view what, std::string_view got, std::string_view expected) {
  return "unknown " + std::string(what) + " '" + std::string(got) + "' (expected " + std::string(expected) + ")";
}

std::optional<std::size_t> JsonNode::choice_index(std::span<const std::string_view> names, std::string_view what) const {
  const auto s = text();
  if (!s) return std::nullopt;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == *s) return i;
  fail(unknown_choice(what, *s, names_list(names)));
  return std::nullopt;
}

}  // namespace synbench::drivers
