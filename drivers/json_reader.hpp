// The one reader of our JSON documents (device profiles, bench configs, sweep plans, the twin
// config, the daemon's config and tokens files). A JsonNode is a cursor: a value (or its
// absence) with the RFC 6901 pointer that leads to it, reporting every problem as a JsonError
// {pointer, reason} into a shared JsonReader. Reading goes on after a problem, so a user fixes a
// document in one pass. The domain rules (ranges across fields, duplicates) stay with each loader.
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "drivers/json_fwd.hpp"
#include "drivers/profile/number_format.hpp"

namespace synbench::drivers {

// One problem in a document: the JSON pointer ("" for the whole document) and what is wrong.
struct JsonError {
  std::string pointer;
  std::string reason;
  bool operator==(const JsonError&) const = default;
};
// "/dimensions/speed_rpm/1: must be > 0"; "(document): ..." for the root.
std::string to_string(const JsonError& e);

// One RFC 6901 reference token: '~' becomes "~0" and '/' becomes "~1".
std::string json_pointer_token(std::string_view key);

// Keys starting with '_' are comments ("_comment", "_assumed") wherever an object is read.
bool is_comment_key(std::string_view key);

// A number check: empty when fine, else the reason.
using NumberCheck = std::function<std::string(double)>;
NumberCheck positive();                                       // "must be > 0"
NumberCheck non_negative();                                   // "must be >= 0"
NumberCheck in_range(double lo, double hi, bool whole = false);  // "must be a whole number", "X is outside [lo, hi]"

class JsonReader {
 public:
  std::vector<JsonError> errors;
  void fail(std::string pointer, std::string reason) { errors.push_back({std::move(pointer), std::move(reason)}); }
  std::size_t count() const { return errors.size(); }
  bool ok() const { return errors.empty(); }
};

class JsonNode {
 public:
  // `value` null means absent (a missing key, or a child of something that is not a container).
  JsonNode(const synbench::Json* value, std::string pointer, JsonReader& reader)
      : value_(value), pointer_(std::move(pointer)), reader_(&reader) {}

  bool present() const { return value_ != nullptr; }
  bool is_null() const;
  const synbench::Json& json() const { return *value_; }  // only when present()
  const std::string& pointer() const { return pointer_; }
  JsonReader& reader() const { return *reader_; }

  // A member (absent when missing or when this is not an object) and a list element.
  JsonNode operator[](std::string_view key) const;
  JsonNode at(std::size_t index) const;
  bool has(std::string_view key) const { return (*this)[key].present(); }

  void fail(std::string reason) const { reader_->fail(pointer_, std::move(reason)); }

  // Reports "required field is missing" when absent; returns *this for chaining.
  const JsonNode& required(std::string_view reason = "required field is missing") const;

  // Each returns false / nullopt when absent (silently) or wrong (reported here).
  bool object(std::string_view reason = "must be a JSON object") const;
  // Reports each member outside `known` as "unknown field" (comment keys allowed).
  void reject_unknown(std::initializer_list<std::string_view> known) const;
  void reject_unknown(std::span<const std::string_view> known) const;
  // The members, comments skipped, in document order (an object checked already).
  std::vector<std::pair<std::string, JsonNode>> members() const;
  // A list: its elements; `non_empty` reports "must not be empty". `reason` when not a list.
  std::optional<std::vector<JsonNode>> list(std::string_view reason = "must be a list", bool non_empty = false) const;

  // A finite number ("must be a finite number"), then `check`.
  std::optional<double> number(const NumberCheck& check = {}) const;
  // A JSON integer within [lo, hi]: "must be an integer in lo..hi", "N is outside lo..hi".
  std::optional<std::int64_t> integer(std::int64_t lo, std::int64_t hi) const;
  // A string ("must be a string"; with non_empty "must be a non-empty string").
  std::optional<std::string> text(bool non_empty = false) const;
  std::optional<bool> boolean() const;  // "must be true or false"
  std::optional<std::vector<std::string>> texts() const;  // "must be a list of strings"

  // One of a set of names: "unknown <what> 'x' (expected a, b, c)". The enum's values are the
  // indices into `names`.
  template <typename E>
  std::optional<E> choice(std::span<const std::string_view> names, std::string_view what) const {
    const auto i = choice_index(names, what);
    if (!i) return std::nullopt;
    return static_cast<E>(*i);
  }
  // Same, for an enum with its own parse function and a names list to show.
  template <typename E, typename Parse>
  std::optional<E> choice(Parse parse, std::string_view what, std::string_view expected) const {
    const auto s = text();
    if (!s) return std::nullopt;
    const std::optional<E> v = parse(*s);
    if (!v) fail(unknown_choice(what, *s, expected));
    return v;
  }

  static std::string unknown_choice(std::string_view what, std::string_view got, std::string_view expected);
  static std::string names_list(std::span<const std::string_view> names);

 private:
  std::optional<std::size_t> choice_index(std::span<const std::string_view> names, std::string_view what) const;

  const synbench::Json* value_;
  std::string pointer_;
  JsonReader* reader_;
};

// The root of `doc` ("" pointer).
inline JsonNode read_root(const synbench::Json& doc, JsonReader& reader) { return JsonNode(&doc, "", reader); }

}  // namespace synbench::drivers
