// Tests of the one JSON reader: each error kind at its RFC 6901 pointer (with '~' and '/'
// escaped), comment keys, unknown fields, required fields, choices that list the names, and
// nested lists; reading goes on after a problem.
#include "drivers/json_reader.hpp"

#include <gtest/gtest.h>

#include <array>

#include "drivers/json.hpp"

namespace synbench::drivers {
namespace {

using Json = synbench::Json;

std::vector<std::string> texts(const JsonReader& r) {
  std::vector<std::string> out;
  for (const JsonError& e : r.errors) out.push_back(to_string(e));
  return out;
}

TEST(JsonReader, PointerTokensEscapeTildeAndSlash) {
  EXPECT_EQ(json_pointer_token("a/b~c"), "a~1b~0c");
  EXPECT_EQ(json_pointer_token("~/"), "~0~1");
  EXPECT_EQ(json_pointer_token("plain"), "plain");
  const Json doc = Json::parse(R"({"a/b": {"c~d": [1, "x"]}})");
  JsonReader r;
  const JsonNode n = read_root(doc, r)["a/b"]["c~d"].at(1);
  EXPECT_EQ(n.pointer(), "/a~1b/c~0d/1");
  EXPECT_FALSE(n.number());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0], (JsonError{"/a~1b/c~0d/1", "must be a finite number"}));
  // The pointer finds the value it names.
  EXPECT_EQ(doc.at(Json::json_pointer(r.errors[0].pointer)), "x");
}

TEST(JsonReader, RootErrorsSayDocument) {
  const Json doc = Json::parse("[1]");
  JsonReader r;
  EXPECT_FALSE(read_root(doc, r).object());
  EXPECT_EQ(texts(r), std::vector<std::string>{"(document): must be a JSON object"});
}

TEST(JsonReader, UnknownFieldsAreReportedAndCommentsAllowed) {
  const Json doc = Json::parse(R"({"_comment": "why", "_assumed": [1], "known": 1, "typo": 2, "x/y": 3})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  root.reject_unknown({"known"});
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/typo: unknown field", "/x~1y: unknown field"}));
  // members() skips the comments too.
  const auto m = root.members();
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].first, "known");
  EXPECT_EQ(m[2].second.pointer(), "/x~1y");
}

TEST(JsonReader, AbsentIsSilentUnlessRequired) {
  const Json doc = Json::parse(R"({"a": 1})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_FALSE(root["b"].number());
  EXPECT_FALSE(root["b"].text());
  EXPECT_FALSE(root["b"]["c"].boolean());  // below an absent node
  EXPECT_TRUE(r.ok());
  EXPECT_FALSE(root["b"].required().number());
  EXPECT_FALSE(root["c"].required("required device is missing").object());
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/b: required field is missing", "/c: required device is missing"}));
}

TEST(JsonReader, Numbers) {
  const Json doc = Json::parse(R"({"s": "1", "neg": -1, "half": 2.5, "big": 70000, "ok": 3, "f": 0.5})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_FALSE(root["s"].number());
  EXPECT_FALSE(root["neg"].number(positive()));
  EXPECT_FALSE(root["half"].number(in_range(0, 10, true)));
  EXPECT_FALSE(root["big"].number(in_range(1, 65535, true)));
  EXPECT_EQ(root["ok"].number(in_range(1, 65535, true)), 3.0);
  EXPECT_EQ(root["f"].number(non_negative()), 0.5);
  EXPECT_FALSE(root["f"].number([](double v) { return v > 1 ? std::string() : "must exceed 1"; }));
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/s: must be a finite number", "/neg: must be > 0",
                                                "/half: must be a whole number", "/big: 70000 is outside [1, 65535]",
                                                "/f: must exceed 1"}));
}

TEST(JsonReader, Integers) {
  const Json doc = Json::parse(R"({"f": 1.5, "lo": 0, "hi": 18446744073709551615, "ok": 247})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_FALSE(root["f"].integer(1, 247));
  EXPECT_FALSE(root["lo"].integer(1, 247));
  EXPECT_FALSE(root["hi"].integer(1, 247));  // above int64: no wrap-around
  EXPECT_EQ(root["ok"].integer(1, 247), 247);
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/f: must be an integer in 1..247", "/lo: 0 is outside 1..247",
                                                "/hi: 18446744073709551615 is outside 1..247"}));
}

TEST(JsonReader, TextsAndBooleans) {
  const Json doc = Json::parse(R"({"n": 1, "e": "", "t": "x", "b": "true", "ok": false, "l": ["a", 2]})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_FALSE(root["n"].text());
  EXPECT_EQ(root["e"].text(), "");
  EXPECT_FALSE(root["e"].text(true));
  EXPECT_EQ(root["t"].text(true), "x");
  EXPECT_FALSE(root["b"].boolean());
  EXPECT_EQ(root["ok"].boolean(), false);
  EXPECT_FALSE(root["l"].texts());
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/n: must be a string", "/e: must be a non-empty string",
                                                "/b: must be true or false", "/l: must be a list of strings"}));
}

enum class Colour { red, green };
constexpr std::array<std::string_view, 2> kColourNames{"red", "green"};

TEST(JsonReader, ChoicesListTheNames) {
  const Json doc = Json::parse(R"({"a": "green", "b": "blue", "c": 3})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_EQ(root["a"].choice<Colour>(kColourNames, "colour"), Colour::green);
  EXPECT_FALSE(root["b"].choice<Colour>(kColourNames, "colour"));
  EXPECT_FALSE(root["c"].choice<Colour>(kColourNames, "colour"));
  const auto parse = [](std::string_view s) { return s == "red" ? std::optional<Colour>(Colour::red) : std::nullopt; };
  EXPECT_FALSE(root["b"].choice<Colour>(parse, "paint", "red only"));
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/b: unknown colour 'blue' (expected red, green)", "/c: must be a string",
                                                "/b: unknown paint 'blue' (expected red only)"}));
}

TEST(JsonReader, NestedListsCarryTheirIndices) {
  const Json doc = Json::parse(R"({"grid": [[1, 2], [3, "x"], 4, []]})");
  JsonReader r;
  const auto rows = read_root(doc, r)["grid"].list("must be a list of rows", true);
  ASSERT_TRUE(rows);
  ASSERT_EQ(rows->size(), 4u);
  double sum = 0;
  for (const JsonNode& row : *rows)
    if (const auto cells = row.list("must be a list of numbers", true))
      for (const JsonNode& cell : *cells) sum += cell.number().value_or(0);
  EXPECT_EQ(sum, 6);
  EXPECT_EQ(texts(r), (std::vector<std::string>{"/grid/1/1: must be a finite number",
                                                "/grid/2: must be a list of numbers", "/grid/3: must not be empty"}));
}

TEST(JsonReader, ChildrenOfWrongTypesAreAbsent) {
  const Json doc = Json::parse(R"({"n": 1, "l": [1]})");
  JsonReader r;
  const JsonNode root = read_root(doc, r);
  EXPECT_FALSE(root["n"]["x"].present());
  EXPECT_FALSE(root["l"].at(1).present());
  EXPECT_FALSE(root["n"].at(0).present());
  EXPECT_EQ(root["l"].at(1).pointer(), "/l/1");
  EXPECT_TRUE(r.ok());
}

}  // namespace
}  // namespace synbench::drivers
