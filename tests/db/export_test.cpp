// CSV and JSON export: header, widths, nulls, quoting, numbers that parse back bit for bit.
#include "db/export.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdlib>
#include <sstream>

#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::sample_record;

std::vector<PointRow> sample_rows(std::int64_t n) {
  std::vector<PointRow> rows;
  for (std::int64_t i = 0; i < n; ++i) rows.push_back({i, sample_record(i)});
  return rows;
}

// A small RFC 4180 reader, enough for the export's own output.
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> out(1, std::vector<std::string>(1));
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        out.back().back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back().back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.back().emplace_back();
    } else if (c == '\n') {
      out.emplace_back(1);
    } else {
      out.back().back() += c;
    }
  }
  if (out.back().size() == 1 && out.back()[0].empty()) out.pop_back();  // after the last LF
  return out;
}

TEST(CsvExport, HeaderIsTheRecordFieldsThenTruthColumns) {
  const std::string expected =
      "point_index,speed_rpm,load_Nm,angle_deg,estimator,pwm,speed_meas_rpm,im_A,id_A,iq_A,ud_V,uq_V,"
      "udc_V,idcm_A,idcg_A,pdcm_W,pdcg_W,pm_W,efficiency,pos_err_min_deg,pos_err_mean_deg,"
      "pos_err_max_deg,speed_err_rpm,ld_est_H,lq_est_H,rs_est_ohm,ld_err_pct,lq_err_pct,rs_err_pct,"
      "temp_C,window_s,samples,settle_s,voltage_limited,unstable,fault,below_min_speed,fallback_fraction,lock_lost,window_source,fault_code_raw,angle_meas_deg,angle_off,"
      "im_u_A,pdcm_u_W,pdcg_u_W,pm_u_W,efficiency_u,im_u_repeat_A,pdcm_u_repeat_W,efficiency_u_repeat,truth_pin_W,truth_pcu_W,"
      "truth_pfe_W,truth_pmech_W,truth_pinvm_W,truth_pm_W,truth_temp_C\n";
  EXPECT_EQ(points_to_csv({}), expected);
}

TEST(CsvExport, HeaderIsToJsonsKeysWithTruthFlattened) {
  // The CSV walks the member table, bench::to_json its own loop: the two must name the same fields.
  bench::PointRecord r;
  r.truth = drivers::TruthWindow{};
  std::vector<std::string> expected{"point_index"};
  const auto j = bench::to_json(r);
  for (const auto& [key, value] : j.items()) {
    if (!value.is_object()) expected.push_back(key);
    else
      for (const auto& [tkey, tvalue] : value.items()) expected.push_back(key + "_" + tkey);
  }
  EXPECT_EQ(csv_columns(), expected);
  EXPECT_EQ(csv_columns().size(), 58u) << "docs/database.md gives the count";
}

TEST(CsvExport, EveryValueReadsBackExactly) {
  const auto rows = sample_rows(30);
  const auto table = parse_csv(points_to_csv(rows));
  ASSERT_EQ(table.size(), rows.size() + 1);
  const auto& header = table[0];
  auto col = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  auto number = [](const std::string& s) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    EXPECT_EQ(*end, '\0') << s;
    return v;
  };
  auto same_bits = [](double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); };

  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& line = table[k + 1];
    const auto& r = rows[k].record;
    ASSERT_EQ(line.size(), header.size()) << "line " << k;
    EXPECT_EQ(line[col("point_index")], std::to_string(rows[k].index));
    // Every number, required or optional, through its text.
    const auto j = bench::to_json(r);
    for (const auto& [key, value] : j.items()) {
      if (key == "truth") continue;
      const auto& cell = line[col(key)];
      if (value.is_null()) {
        EXPECT_EQ(cell, "") << key;
      } else if (value.is_number_float()) {
        EXPECT_TRUE(same_bits(number(cell), value.get<double>())) << key << " " << cell;
      }
    }
    EXPECT_EQ(line[col("estimator")], std::string(drivers::name(r.estimator)));
    EXPECT_EQ(line[col("window_source")], drivers::keeper_name(r.window_source));
    EXPECT_EQ(line[col("fault_code_raw")], r.fault_code_raw ? std::to_string(*r.fault_code_raw) : "");
    EXPECT_EQ(line[col("angle_off")], r.angle_off ? "true" : "false");
    EXPECT_EQ(line[col("samples")], std::to_string(r.samples));
    EXPECT_EQ(line[col("voltage_limited")], r.voltage_limited ? "true" : "false");
    EXPECT_EQ(line[col("fault")], r.fault.value_or(""));
    if (r.truth) {
      EXPECT_TRUE(same_bits(number(line[col("truth_pmech_W")]), r.truth->pmech_W));
      EXPECT_TRUE(same_bits(number(line[col("truth_pfe_W")]), -0.0));
      EXPECT_TRUE(same_bits(number(line[col("truth_pinvm_W")]), r.truth->pinvm_W));
    } else {
      for (const char* t : {"truth_pin_W", "truth_pm_W", "truth_temp_C"}) EXPECT_EQ(line[col(t)], "");
    }
  }
}

TEST(CsvExport, QuotesTextThatNeedsIt) {
  auto r = sample_record(8);
  ASSERT_EQ(r.fault, "link_loss, \"quoted\"");
  const std::vector<PointRow> rows{{8, r}};
  EXPECT_NE(points_to_csv(rows).find(",\"link_loss, \"\"quoted\"\"\","), std::string::npos);
}

TEST(CsvExport, ShortestNumbersAndSpecialValues) {
  bench::PointRecord r;
  r.speed_rpm = 0.1;
  r.load_Nm = 1500;
  r.angle_deg = std::numeric_limits<double>::infinity();
  r.efficiency = std::numeric_limits<double>::quiet_NaN();
  const std::vector<PointRow> rows{{0, r}};
  const auto table = parse_csv(points_to_csv(rows));
  EXPECT_EQ(table[1][1], "0.1");
  EXPECT_EQ(table[1][2], "1500");
  EXPECT_EQ(table[1][3], "inf");
  EXPECT_EQ(table[1][18], "nan");
}

TEST(JsonExport, ArrayOfRecordObjectsWithTheirIndex) {
  auto rows = sample_rows(4);
  rows[1].index = 7;  // export keeps the stored index, not the position
  const auto j = points_to_json(rows);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 4u);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& o = j[k];
    ASSERT_TRUE(o.is_object());
    EXPECT_EQ(o.begin().key(), "point_index");
    EXPECT_EQ(o["point_index"], rows[k].index);
    auto without_index = o;
    without_index.erase("point_index");
    EXPECT_EQ(without_index.dump(), bench::to_json(rows[k].record).dump()) << "same fields, same order";
  }
  EXPECT_TRUE(j[0]["truth"].is_null());
  EXPECT_TRUE(j[1]["truth"].is_object());
  EXPECT_EQ(points_to_json({}).dump(), "[]");
}

}  // namespace
}  // namespace synbench::db
