// The sweep routes over a real store and the real-time twin, through the Router without a socket:
// plan bodies refused by the published schema are `bad_plan` at their pointer (the parser's own
// errors still come through), and the live answers of the run history, a sweep, its points and
// its analysis conform to the schemas /api/openapi.json publishes for them.
#include "server/http/sweep_routes.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>

#include "app/bench_backend.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/json_schema.hpp"
#include "bench/point_record.hpp"
#include "bench/sweep_plan_angle_search.hpp"

namespace synbench::http {
namespace {

std::filesystem::path make_temp_dir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "synbench-sweep-routes-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

db::Store open_store(const std::filesystem::path& path) {
  auto s = db::Store::open(path);
  if (!s) throw std::runtime_error("cannot open the store: " + s.error().message);
  return std::move(*s);
}

struct SweepRoutes : ::testing::Test {
  SweepRoutes()
      : dir(make_temp_dir()),
        store(open_store(dir / "synbench.db")),
        bench(cli::make_backend(std::nullopt, emulator::TwinConfig{}), [](const BenchStatus& s) { return status_json(s).dump(); }),
        router([](std::string_view t) -> std::optional<Identity> {
          if (t == "op") return Identity{Role::operator_, "op"};
          if (t == "view") return Identity{Role::viewer, "view"};
          return std::nullopt;
        }) {
    add_api_routes(router, {bench, twin, control, metrics, "test"});
    add_sweep_routes(router, store, bench, control, worker, dir / "synbench.db", synbench::Json::object());
    bench.start();
  }
  ~SweepRoutes() override {
    worker.stop();
    bench.shutdown();
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  Response call(const std::string& method, const std::string& target, const std::string& body = "", const std::string& token = "op") {
    return router.dispatch(method, target, "Bearer " + token, body);
  }
  std::filesystem::path dir;
  db::Store store;
  emulator::TwinConfig twin;
  BenchRuntime bench;
  ControlLock control;
  HttpMetrics metrics;
  Worker worker;
  Router router;
};

std::string error_text(const Response& r) {
  const auto doc = synbench::Json::parse(r.body);
  return doc["error"]["code"].get<std::string>() + " " + doc["error"]["message"].get<std::string>();
}

// The estimate's body is checked on the worker thread (Worker::offloaded), the create's by the
// router: the same answers either way.
TEST_F(SweepRoutes, PlanBodiesAreRefusedAtTheirPointer) {
  for (const char* route : {"/api/sweeps", "/api/sweeps/estimate"}) {
    // The published top level, checked by the router: every problem, in the body's order.
    auto r = call("POST", route, R"({"mode": "random", "window_s": 0, "notes": [1], "preset": 3})");
    EXPECT_EQ(r.status, 400) << route;
    EXPECT_EQ(error_text(r),
              "bad_plan /mode: must be one of grid, adaptive (got 'random'); /window_s: 0 is outside [0.1, 3600]; "
              "/notes/0: must be a string; /preset: must be a string or an object")
        << route;
    r = call("POST", route, "[]");
    EXPECT_EQ(error_text(r), "bad_plan (document): must be an object") << route;
    r = call("POST", route, R"({"dimensions": )");
    EXPECT_EQ(r.status, 400);
    EXPECT_EQ(error_text(r).rfind("bad_json ", 0), 0u) << error_text(r);
    // The rest is the plan parser's, at its pointers as before.
    r = call("POST", route, R"({"dimensions": {"speed_rpm": {"from": 1, "to": 2, "step": 0}}})");
    EXPECT_EQ(r.status, 400);
    EXPECT_NE(error_text(r).find("bad_plan /dimensions/speed_rpm"), std::string::npos) << error_text(r);
  }
}

// Every GET answer with a published schema, on a store holding a sweep with two points.
TEST_F(SweepRoutes, LiveAnswersConformToThePublishedSchemas) {
  const auto created = call("POST", "/api/sweeps", R"({"name": "schema check", "dimensions": {"speed_rpm": [300], "load_Nm": [0.5], "angle_deg": [40, 50]}})");
  ASSERT_EQ(created.status, 201) << created.body;
  const auto id = synbench::Json::parse(created.body)["id"].get<std::int64_t>();
  for (std::int64_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(store.insert_point(id, i, bench::PointRecord{}));
  }
  const auto doc = synbench::Json::parse(call("GET", "/api/openapi.json").body);
  const std::string sid = std::to_string(id);
  std::size_t checked = 0;
  for (const auto& [pattern, methods] : doc["paths"].items()) {
    if (!methods.contains("get")) continue;
    const auto& ok = methods["get"]["responses"]["200"];
    if (!ok.contains("content")) continue;
    std::string target = pattern;
    if (const auto at = target.find("{id}"); at != std::string::npos) target.replace(at, 4, sid);
    const auto answer = call("GET", target);
    ASSERT_EQ(answer.status, 200) << target << ": " << answer.body;
    if (!ok["content"].contains("application/json")) {  // the report (text/html) and its CSV (text/csv)
      const std::string type = ok["content"].items().begin().key();
      EXPECT_EQ(answer.content_type.rfind(type, 0), 0u) << target << ": " << answer.content_type;
      EXPECT_FALSE(answer.body.empty()) << target;
      ++checked;
      continue;
    }
    const auto& schema = ok["content"]["application/json"]["schema"];
    const auto errors = validate(schema, synbench::Json::parse(answer.body));
    EXPECT_TRUE(errors.empty()) << "GET " << target << ": " << to_string(errors);
    ++checked;
  }
  // status, health, config, lock, whoami, estimators, presets, sweeps, sweep, points, analysis, report, report.csv
  EXPECT_GE(checked, 13u);
  // The one POST with a published 200 answer.
  const auto estimate = call("POST", "/api/sweeps/estimate", R"({"preset": "thesis-grid"})", "view");
  ASSERT_EQ(estimate.status, 200) << estimate.body;
  const auto& estimate_schema = doc["paths"]["/api/sweeps/estimate"]["post"]["responses"]["200"]["content"]["application/json"]["schema"];
  EXPECT_EQ(to_string(validate(estimate_schema, synbench::Json::parse(estimate.body))), "");
  const auto points = synbench::Json::parse(call("GET", "/api/sweeps/" + sid + "/points").body);
  EXPECT_EQ(points.size(), 2u);
  // And the schema is not a formality: an answer missing a member fails it.
  auto sweep = synbench::Json::parse(call("GET", "/api/sweeps/" + sid).body);
  sweep.erase("points_stored");
  const auto& sweep_schema = doc["paths"]["/api/sweeps/{id}"]["get"]["responses"]["200"]["content"]["application/json"]["schema"];
  EXPECT_EQ(to_string(validate(sweep_schema, sweep)), "/points_stored: required field is missing");
}

// An adaptive plan with an angle u target and a precision target, created over REST: the
// analysis carries the searches replayed from the stored points (sweep_outcome), and conforms.
TEST_F(SweepRoutes, AnalysisCarriesTheSweepOutcome) {
  const auto created = call("POST", "/api/sweeps", R"({"name": "until sure", "mode": "adaptive",
    "dimensions": {"speed_rpm": [300], "load_Nm": [2]},
    "adaptive": {"angle_u_target_deg": 0.5, "max_evaluations": 25},
    "precision": {"pdcm_u_repeat_target_W": 0.04, "max_window_s": 4}})");
  ASSERT_EQ(created.status, 201) << created.body;
  const auto id = synbench::Json::parse(created.body)["id"].get<std::int64_t>();
  // Stored as the engine stores them: the search's proposals at group * max_evaluations + e.
  bench::AngleSearchOptions opt;
  opt.max_evaluations = 25;
  opt.angle_u_target_deg = 0.5;
  bench::AngleSearch search(opt);
  std::size_t e = 0;
  while (auto a = search.next_angle()) {
    bench::PointRecord r;
    r.speed_rpm = 300;
    r.load_Nm = 2;
    r.angle_deg = *a;
    r.im_A = 2 * (1 + 4e-4 * (*a - 51.3) * (*a - 51.3));
    r.pdcm_W = 60 + 0.01 * (*a - 53.1) * (*a - 53.1);
    r.im_u_A = r.im_u_repeat_A = 0.002;
    r.pdcm_u_W = r.pdcm_u_repeat_W = e == 0 ? 0.05 : 0.03;  // the first point above the 0.04 W target
    search.report(r.angle_deg, r.im_A, r.pdcm_W, r.im_u_repeat_A, r.pdcm_u_repeat_W);
    ASSERT_TRUE(store.insert_point(id, static_cast<std::int64_t>(e++), r));
  }
  const auto answer = call("GET", "/api/sweeps/" + std::to_string(id) + "/analysis", "", "view");
  ASSERT_EQ(answer.status, 200) << answer.body;
  const auto j = synbench::Json::parse(answer.body);
  const auto& o = j["sweep_outcome"];
  ASSERT_TRUE(o["adaptive"].is_object()) << answer.body;
  EXPECT_EQ(o["adaptive"]["points_used"], e);
  EXPECT_EQ(o["adaptive"]["grid_points"], 19);
  EXPECT_EQ(o["adaptive"]["curves_target_met"], 1);
  EXPECT_EQ(o["adaptive"]["curves"][0]["angle_u_target_met"], true);
  EXPECT_LE(o["adaptive"]["curves"][0]["mtpa"]["angle_u_deg"].get<double>(), 0.5);
  EXPECT_EQ(o["precision"]["points_missed"], 1);
  EXPECT_EQ(o["precision"]["missed_indices"], synbench::Json::array({0}));
  const auto doc = synbench::Json::parse(call("GET", "/api/openapi.json").body);
  const auto& schema =
      doc["paths"]["/api/sweeps/{id}/analysis"]["get"]["responses"]["200"]["content"]["application/json"]["schema"];
  EXPECT_EQ(to_string(validate(schema, j)), "");
  // The estimate of the same plan is an upper bound with the longer windows.
  const auto est = call("POST", "/api/sweeps/estimate", R"({"dimensions": {"speed_rpm": [300], "load_Nm": [2], "angle_deg": [50]},
    "precision": {"pdcm_u_repeat_target_W": 0.04, "max_window_s": 4}})", "view");
  ASSERT_EQ(est.status, 200) << est.body;
  const auto ej = synbench::Json::parse(est.body);
  EXPECT_EQ(ej["upper_bound"], true);
  EXPECT_GT(ej["precision_extra_s"].get<double>(), 8.0);  // twice at least the 4 s cap
  EXPECT_EQ(ej["plan"]["precision"]["max_window_s"], 4.0);
  // Refused at its pointer over REST as on the command line.
  const auto bad = call("POST", "/api/sweeps/estimate", R"({"dimensions": {"speed_rpm": [300], "load_Nm": [2], "angle_deg": [50]},
    "precision": {"pdcm_u_repeat_target_W": -1}})", "view");
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(error_text(bad).find("/precision/pdcm_u_repeat_target_W: must be within (0, 1000] W"), std::string::npos)
      << error_text(bad);
}

}  // namespace
}  // namespace synbench::http
