// A validator for the subset of JSON Schema (OpenAPI 3.0 dialect) that the daemon publishes in
// /api/openapi.json: the router checks request bodies with it and the tests check the handlers'
// answers with it, so the published document is the check itself and cannot drift from it.
// A schema keyword outside the subset is refused by check_schema (the router runs it when a
// route is added), so nothing is published that is not enforced.
//
// Keywords: type (null excluded; `nullable: true` admits null), properties, required,
// additionalProperties (false or a schema), minProperties, minimum, maximum, exclusiveMinimum
// and exclusiveMaximum (3.0 booleans), enum, items, minItems, maxItems, minLength, maxLength
// (in code points), oneOf; description is an annotation.
#pragma once

#include <string>
#include <vector>

#include "drivers/json_fwd.hpp"

namespace synbench::http {

struct SchemaError {
  std::string pointer;  // JSON pointer (RFC 6901) into the checked value, "" for the whole
  std::string reason;
};
// "/speed_rpm: 9000 is outside [0, 1500]"; the whole value is "(document)".
std::string to_string(const SchemaError& e);
// The errors as one message, "; " between them.
std::string to_string(const std::vector<SchemaError>& errors);

// Every problem of `value` against `schema`, each at its pointer (empty: it conforms). `schema`
// must have passed check_schema.
std::vector<SchemaError> validate(const synbench::Json& schema, const synbench::Json& value);

// Problems of the schema itself, each at its pointer into the schema: a keyword the validator
// does not implement, or a keyword's value of the wrong kind.
std::vector<SchemaError> check_schema(const synbench::Json& schema);

}  // namespace synbench::http
