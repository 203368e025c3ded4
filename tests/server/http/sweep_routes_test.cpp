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
              "bad_plan /mode: must be one of grid, adaptive (got 'random'); /window_s: 0 is outside (0, 3600]; "
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

}  // namespace
}  // namespace synbench::http
