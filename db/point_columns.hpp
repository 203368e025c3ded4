// The points table's columns that hold a PointRecord: bench's member table
// (bench/point_record_fields.hpp) as SQL column names, and a record bound to a statement's
// parameters and read back from a row, field by field. Internal to db/.
#pragma once

#include <string>
#include <tuple>
#include <vector>

#include "bench/point_record_fields.hpp"
#include "db/error.hpp"

namespace synbench::db::detail {

class Statement;  // SQLite (db/sqlite.hpp)
class PgParams;   // PostgreSQL (db/pg.hpp)
class PgRow;

// One column per field of the table, in its order; a field with a table of its own (truth) is
// one column of JSON text named "<field>_json".
inline constexpr int kRecordColumnCount = static_cast<int>(std::tuple_size_v<decltype(bench::kPointRecordFields)>);
const std::vector<std::string>& record_columns();

// Binds the record to parameters first, first + 1, ... in record_columns()' order. A NaN (which
// SQLite cannot store) is bound as NULL: in a required number it reads back as NaN.
// For Statement and PgParams.
template <class Params>
void bind_record(Params& st, int first, const bench::PointRecord& r);
// Reads the record from a row's columns first, first + 1, ...: errc::bad_record naming the
// column for a value the record cannot hold.
// For Statement and PgRow.
template <class Row>
Status read_record(const Row& st, int first, bench::PointRecord& r);

}  // namespace synbench::db::detail
