// Stored points as CSV and JSON, in the record's one schema (experiment.md Sec. 2.5).
#pragma once

#include "drivers/json.hpp"

#include <span>
#include <string>
#include <vector>

#include "db/types.hpp"

namespace synbench::db {

// CSV column names: point_index, then the record's fields in order (bench::to_json's keys), then
// the truth object flattened as truth_pin_W ... truth_temp_C.
std::vector<std::string> csv_columns();

// One header line and one line per row, LF line ends. Numbers in their shortest round-trip form
// (std::to_chars: parsing them gives back the same double); nulls (optional fields, fault, truth
// on hardware) as empty fields; NaN and infinities as nan, inf, -inf; booleans as true/false;
// text quoted as RFC 4180 asks when it holds a comma, quote or line break.
std::string points_to_csv(std::span<const PointRow> rows);

// An array with one object per row: "point_index" first, then exactly bench::to_json's fields.
synbench::Json points_to_json(std::span<const PointRow> rows);

}  // namespace synbench::db
