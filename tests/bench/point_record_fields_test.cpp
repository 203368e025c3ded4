// The point record's member table against everything that lists the record's fields: the struct
// (every member once), to_json's keys, to_text's lines and docs/record.md's field table.
#include "bench/point_record_fields.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "drivers/json.hpp"

namespace synbench::bench {
namespace {

template <class Fields>
std::vector<std::string> names(const Fields& fields) {
  std::vector<std::string> out;
  for (const auto n : field_names(fields)) out.emplace_back(n);
  return out;
}

std::vector<std::string> keys(const synbench::Json& j) {
  std::vector<std::string> out;
  for (const auto& [key, value] : j.items()) out.push_back(key);
  return out;
}

// Each field's byte offset in its struct: distinct offsets, as many as the struct has members,
// mean the table names every member exactly once (the static_assert checks the count alone).
template <class S>
std::set<std::ptrdiff_t> member_offsets() {
  S s{};
  std::set<std::ptrdiff_t> out;
  for_each_field(FieldTable<S>::fields, [&](const auto& f) {
    out.insert(reinterpret_cast<const char*>(&(s.*f.member)) - reinterpret_cast<const char*>(&s));
  });
  return out;
}

TEST(PointRecordFields, NameEveryMemberOnce) {
  EXPECT_EQ(member_offsets<PointRecord>().size(), detail::member_count<PointRecord>());
  EXPECT_EQ(member_offsets<drivers::TruthWindow>().size(), detail::member_count<drivers::TruthWindow>());
}

// The count behind the static_asserts sees members of every kind a record holds, so a member
// added to PointRecord and not to its table cannot compile.
TEST(PointRecordFields, MemberCountSeesEveryKindOfMember) {
  struct Kinds {
    double a = 0;
    std::optional<double> b;
    drivers::Estimator c{};
    drivers::Pwm d{};
    std::uint32_t e = 0;
    bool f = false;
    std::optional<std::string> g;
    drivers::WindowKeeper h{};
    std::optional<std::int64_t> i;
    std::optional<drivers::TruthWindow> j;
    drivers::TruthWindow k;  // a nested aggregate is one member, not seven
  };
  static_assert(detail::member_count<Kinds>() == 11);
  EXPECT_EQ(detail::member_count<Kinds>(), 11u);
}

TEST(PointRecordFields, AreToJsonsKeysInOrder) {
  PointRecord r;
  EXPECT_EQ(keys(to_json(r)), names(kPointRecordFields));
  EXPECT_TRUE(to_json(r)["truth"].is_null());
  r.truth = drivers::TruthWindow{};
  EXPECT_EQ(keys(to_json(r)["truth"]), names(kTruthFields));
  EXPECT_EQ(keys(to_json(*r.truth)), names(kTruthFields));
}

TEST(PointRecordFields, ToJsonWritesEachKindOfValue) {
  PointRecord r;
  r.estimator = drivers::Estimator::eemf_lut;
  r.pwm = drivers::Pwm::aspwm;
  r.window_source = drivers::WindowKeeper::host;
  r.samples = 4'000'000'000u;
  r.unstable = true;
  r.pos_err_mean_deg = -0.0;
  r.fault = "unknown";
  r.fault_code_raw = -5;
  r.truth = drivers::TruthWindow{.pin_W = 1.5, .temp_C = 41};
  const auto j = to_json(r);
  EXPECT_EQ(j["estimator"], "eemf-lut");
  EXPECT_EQ(j["pwm"], "aspwm");
  EXPECT_EQ(j["window_source"], "host");
  EXPECT_EQ(j["samples"], 4'000'000'000u);
  EXPECT_EQ(j["unstable"], true);
  EXPECT_EQ(j["pos_err_mean_deg"].dump(), "-0.0");
  EXPECT_TRUE(j["pos_err_min_deg"].is_null());
  EXPECT_EQ(j["fault"], "unknown");
  EXPECT_EQ(j["fault_code_raw"], -5);
  EXPECT_EQ(j["truth"].dump(),
            R"({"pin_W":1.5,"pcu_W":0.0,"pfe_W":0.0,"pmech_W":0.0,"pinvm_W":0.0,"pm_W":0.0,"temp_C":41.0})");
}

TEST(PointRecordFields, EnumTextReadsBack) {
  for (const auto e : {drivers::Estimator::encoder, drivers::Estimator::eemf_rls})
    EXPECT_EQ(parse_field_text(field_text(e), static_cast<drivers::Estimator*>(nullptr)), e);
  for (const auto k : {drivers::WindowKeeper::device, drivers::WindowKeeper::host})
    EXPECT_EQ(parse_field_text(field_text(k), static_cast<drivers::WindowKeeper*>(nullptr)), k);
  EXPECT_FALSE(parse_field_text("Host", static_cast<drivers::WindowKeeper*>(nullptr)));
  EXPECT_FALSE(parse_field_text("", static_cast<drivers::Pwm*>(nullptr)));
}

TEST(PointRecordFields, ToTextHasOneLinePerFieldInOrder) {
  PointRecord r;
  r.truth = drivers::TruthWindow{};
  std::istringstream text(to_text(r));
  std::vector<std::string> fields, truth;
  for (std::string line; std::getline(text, line);) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (line.rfind("    ", 0) == 0) truth.push_back(first);  // indented under the truth heading
    else if (first != "truth") fields.push_back(first);
  }
  auto expected = names(kPointRecordFields);
  expected.pop_back();  // truth: a heading, then its own lines
  EXPECT_EQ(fields, expected);
  EXPECT_EQ(truth, names(kTruthFields));
}

// docs/record.md's field table: the backquoted names of its "field" column, in order, and the
// truth row's list of the plant's values.
struct Documented {
  std::vector<std::string> fields, truth;
};

Documented documented_fields() {
  std::ifstream in(std::string(SYNBENCH_SOURCE_DIR) + "/docs/record.md");
  EXPECT_TRUE(in) << "docs/record.md";
  Documented d;
  bool in_table = false;
  const std::regex name("`([^`]+)`");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| group | field | meaning |", 0) == 0) {
      in_table = true;
      continue;
    }
    if (!in_table || line.rfind("|---", 0) == 0) continue;
    if (line.rfind("|", 0) != 0) break;  // the table ends at its first line that is no row
    // | group | field | meaning |
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream row(line.substr(1));
    while (std::getline(row, cell, '|')) cells.push_back(cell);
    EXPECT_GE(cells.size(), 3u) << line;
    if (cells.size() < 3) continue;
    for (std::sregex_iterator it(cells[1].begin(), cells[1].end(), name), end; it != end; ++it)
      d.fields.push_back((*it)[1]);
    if (cells[1].find("`truth`") != std::string::npos)
      for (std::sregex_iterator it(cells[2].begin(), cells[2].end(), name), end; it != end; ++it)
        d.truth.push_back((*it)[1]);
  }
  return d;
}

TEST(PointRecordFields, AreTheFieldsDocumentedInRecordMdInOrder) {
  const auto d = documented_fields();
  EXPECT_EQ(d.fields, names(kPointRecordFields)) << "docs/record.md's field table";
  EXPECT_EQ(d.truth, names(kTruthFields)) << "docs/record.md's truth row";
}

}  // namespace
}  // namespace synbench::bench
