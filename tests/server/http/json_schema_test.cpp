// The JSON Schema subset's validator: each keyword, the pointers it reports (escaped), nullable,
// and the schema check that refuses a keyword it does not implement.
#include "server/http/json_schema.hpp"

#include <gtest/gtest.h>

#include "drivers/json.hpp"

namespace synbench::http {
namespace {

using Json = synbench::Json;

// The errors as "pointer: reason" lines, for readable expectations.
std::string problems(const Json& schema, const Json& value) {
  EXPECT_TRUE(check_schema(schema).empty()) << to_string(check_schema(schema));
  return to_string(validate(schema, value));
}

TEST(JsonSchema, TypeAndNullable) {
  EXPECT_EQ(problems({{"type", "boolean"}}, true), "");
  EXPECT_EQ(problems({{"type", "boolean"}}, 1), "(document): must be true or false");
  EXPECT_EQ(problems({{"type", "string"}}, nullptr), "(document): must be a string");
  EXPECT_EQ(problems({{"type", "string"}, {"nullable", true}}, nullptr), "");
  EXPECT_EQ(problems({{"type", "string"}, {"nullable", true}}, 3), "(document): must be a string or null");
  EXPECT_EQ(problems({{"type", "number"}}, 2.5), "");
  EXPECT_EQ(problems({{"type", "number"}}, "2.5"), "(document): must be a number");
  EXPECT_EQ(problems({{"type", "integer"}}, 2), "");
  EXPECT_EQ(problems({{"type", "integer"}}, 2.0), "");  // 3.0: a number without a fraction
  EXPECT_EQ(problems({{"type", "integer"}}, 2.5), "(document): must be an integer");
  EXPECT_EQ(problems({{"type", "object"}}, Json::array()), "(document): must be an object");
  EXPECT_EQ(problems({{"type", "array"}}, Json::object()), "(document): must be an array");
  EXPECT_EQ(problems(Json::object(), nullptr), "");  // no type: anything
}

TEST(JsonSchema, PropertiesRequiredAndAdditionalProperties) {
  const Json schema = {{"type", "object"},
                       {"required", Json::array({"a"})},
                       {"additionalProperties", false},
                       {"properties", {{"a", {{"type", "integer"}}}, {"b", {{"type", "string"}}}}}};
  EXPECT_EQ(problems(schema, {{"a", 1}, {"b", "x"}}), "");
  EXPECT_EQ(problems(schema, {{"b", "x"}}), "/a: required field is missing");
  EXPECT_EQ(problems(schema, {{"a", 1}, {"c", 2}}), "/c: unknown field (expected: a, b)");
  // Every problem, not only the first.
  EXPECT_EQ(problems(schema, {{"b", 1}, {"c", 2}}), "/a: required field is missing; /b: must be a string; /c: unknown field (expected: a, b)");
  const Json open = {{"type", "object"}, {"properties", {{"a", {{"type", "integer"}}}}}};
  EXPECT_EQ(problems(open, {{"a", 1}, {"z", "anything"}}), "");
  const Json typed = {{"type", "object"}, {"additionalProperties", {{"type", "number"}}}};
  EXPECT_EQ(problems(typed, {{"x", 1}, {"y", "no"}}), "/y: must be a number");
}

TEST(JsonSchema, MinPropertiesNamesTheFields) {
  const Json schema = {{"type", "object"}, {"minProperties", 1}, {"properties", {{"a", Json::object()}, {"b", Json::object()}}}};
  EXPECT_EQ(problems(schema, Json::object()), "(document): give at least 1 of a, b");
  EXPECT_EQ(problems(schema, {{"b", 0}}), "");
}

TEST(JsonSchema, BoundsWithThe30ExclusiveFlags) {
  const Json closed = {{"type", "number"}, {"minimum", 0}, {"maximum", 1500}};
  EXPECT_EQ(problems(closed, 0), "");
  EXPECT_EQ(problems(closed, 1500), "");
  EXPECT_EQ(problems(closed, 9000), "(document): 9000 is outside [0, 1500]");
  EXPECT_EQ(problems(closed, -0.5), "(document): -0.5 is outside [0, 1500]");
  const Json open = {{"type", "number"}, {"minimum", 0}, {"exclusiveMinimum", true}, {"maximum", 90}, {"exclusiveMaximum", true}};
  EXPECT_EQ(problems(open, 45), "");
  EXPECT_EQ(problems(open, 0), "(document): 0 is outside (0, 90)");
  EXPECT_EQ(problems(open, 90), "(document): 90 is outside (0, 90)");
  EXPECT_EQ(problems({{"minimum", 1}}, 0), "(document): 0 must be at least 1");
  EXPECT_EQ(problems({{"minimum", 1}, {"exclusiveMinimum", true}}, 1), "(document): 1 must be above 1");
  EXPECT_EQ(problems({{"maximum", 1}}, 2), "(document): 2 must be at most 1");
  EXPECT_EQ(problems({{"maximum", 1}, {"exclusiveMaximum", true}}, 1), "(document): 1 must be below 1");
}

TEST(JsonSchema, Enum) {
  const Json schema = {{"type", "string"}, {"enum", Json::array({"capwm", "aspwm"})}};
  EXPECT_EQ(problems(schema, "aspwm"), "");
  EXPECT_EQ(problems(schema, "magic"), "(document): must be one of capwm, aspwm (got 'magic')");
  EXPECT_EQ(problems({{"enum", Json::array({1, true})}}, false), "(document): must be one of 1, true (got false)");
}

TEST(JsonSchema, ItemsAndTheirCount) {
  const Json schema = {{"type", "array"}, {"minItems", 1}, {"maxItems", 2}, {"items", {{"type", "string"}}}};
  EXPECT_EQ(problems(schema, Json::array({"a"})), "");
  EXPECT_EQ(problems(schema, Json::array()), "(document): must have at least 1 items");
  EXPECT_EQ(problems(schema, Json::array({"a", "b", "c"})), "(document): must have at most 2 items");
  EXPECT_EQ(problems(schema, Json::array({"a", 2})), "/1: must be a string");
}

TEST(JsonSchema, StringLengthInCodePoints) {
  const Json schema = {{"type", "string"}, {"minLength", 2}, {"maxLength", 3}};
  EXPECT_EQ(problems(schema, "ab"), "");
  EXPECT_EQ(problems(schema, "\xC3\xA4\xC3\xB6\xC3\xBC"), "");  // three characters, six bytes
  EXPECT_EQ(problems(schema, "a"), "(document): must be at least 2 characters long");
  EXPECT_EQ(problems(schema, "abcd"), "(document): must be at most 3 characters long");
}

TEST(JsonSchema, OneOf) {
  const Json schema = {{"oneOf", Json::array({{{"type", "string"}}, {{"type", "object"}}})}};
  EXPECT_EQ(problems(schema, "thesis-grid"), "");
  EXPECT_EQ(problems(schema, {{"name", "x"}}), "");
  EXPECT_EQ(problems(schema, 3), "(document): must be a string or an object");
  const Json both = {{"oneOf", Json::array({{{"type", "number"}}, {{"type", "integer"}}})}};
  EXPECT_EQ(problems(both, 2), "(document): matches 2 of its forms where one is allowed");
  EXPECT_EQ(problems(both, 2.5), "");
}

TEST(JsonSchema, PointersAreEscapedAndNested) {
  const Json schema = {{"type", "object"},
                       {"properties", {{"a/b", {{"type", "object"}, {"properties", {{"m~n", {{"type", "array"}, {"items", {{"type", "integer"}}}}}}}}}}}};
  EXPECT_EQ(problems(schema, {{"a/b", {{"m~n", Json::array({1, "x"})}}}}), "/a~1b/m~0n/1: must be an integer");
}

TEST(JsonSchema, UnknownKeywordsAreRefused) {
  EXPECT_TRUE(check_schema({{"type", "object"}, {"description", "x"}}).empty());
  // Each refused where it sits, so a route's author sees which schema and keyword.
  const auto errors = check_schema({{"type", "object"},
                                    {"properties", {{"a", {{"type", "string"}, {"pattern", "^x"}}}}},
                                    {"items", {{"$ref", "#/components/schemas/X"}}},
                                    {"oneOf", Json::array({{{"format", "date"}}})}});
  ASSERT_EQ(errors.size(), 3u) << to_string(errors);
  EXPECT_EQ(errors[0].pointer, "/properties/a/pattern");
  EXPECT_NE(errors[0].reason.find("not implemented"), std::string::npos);
  EXPECT_EQ(errors[1].pointer, "/items/$ref");
  EXPECT_EQ(errors[2].pointer, "/oneOf/0/format");
  EXPECT_EQ(to_string(check_schema({{"type", "float"}})), "/type: must be one of object, array, string, number, integer, boolean");
  EXPECT_EQ(to_string(check_schema({{"exclusiveMinimum", 0}})), "/exclusiveMinimum: must be true or false; /exclusiveMinimum: needs minimum");
  EXPECT_EQ(to_string(check_schema({{"required", Json::array({1})}})), "/required: must be an array of strings");
  EXPECT_EQ(to_string(check_schema({{"minItems", -1}})), "/minItems: must be a whole number");
  EXPECT_EQ(to_string(check_schema("object")), "(document): a schema must be an object");
}

}  // namespace
}  // namespace synbench::http
