// The REST routes on the real-time twin, called through the Router without a socket: every
// mutating route needs an operator, bodies are refused at their JSON pointer by the published
// schemas, the live answers conform to the published answer schemas, and the twin follows a
// speed setpoint.
#include "server/http/api_routes.hpp"

#include "app/bench_backend.hpp"
#include "drivers/profile/number_format.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/http/json_schema.hpp"
#include "server/http/metrics_text.hpp"
#include "tests/docs/generated_section.hpp"
#include "server/http/response_schemas.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <set>
#include <thread>

#include <gtest/gtest.h>

namespace synbench::http {
namespace {

struct Api : ::testing::Test {
  Api() : bench(cli::make_backend(std::nullopt, emulator::TwinConfig{}), [](const BenchStatus& s) { return status_json(s).dump(); }),
          router([](std::string_view t) -> std::optional<Identity> {
            if (t == "op") return Identity{Role::operator_, "op"};
            if (t == "op2") return Identity{Role::operator_, "op2"};
            if (t == "view") return Identity{Role::viewer, "view"};
            return std::nullopt;
          }) {
    add_api_routes(router, {bench, twin, control, metrics, "test"});
    bench.start();
  }
  ~Api() override { bench.shutdown(); }
  Response post(const std::string& path, const std::string& body, const std::string& token = "op") {
    return router.dispatch("POST", path, token.empty() ? "" : "Bearer " + token, body);
  }
  emulator::TwinConfig twin;
  BenchRuntime bench;
  ControlLock control;
  HttpMetrics metrics;
  Router router;
};

// ... but the E-stop, which every signed-in role may press (and which names who did).
TEST_F(Api, EveryMutatingRouteNeedsAnOperator) {
  for (const auto& r : router.routes()) {
    if (r.method == "GET" || r.pattern == "/api/bench/estop") continue;
    EXPECT_EQ(r.role, Role::operator_) << r.pattern;
    EXPECT_EQ(router.dispatch(r.method, r.pattern, "", "{}").status, 401) << r.pattern;
    EXPECT_EQ(router.dispatch(r.method, r.pattern, "Bearer view", "{}").status, 403) << r.pattern;
  }
}

TEST_F(Api, AViewerMayEstopButNotResetOrEnable) {
  EXPECT_EQ(post("/api/bench/estop", "", "").status, 401);
  const auto e = post("/api/bench/estop", "", "view");
  ASSERT_EQ(e.status, 200) << e.body;
  const auto s = synbench::Json::parse(e.body);
  EXPECT_EQ(s["supervisor"]["phase"], "estopped");
  EXPECT_EQ(s["supervisor"]["trip"]["detail"], "E-stop by view (viewer)");
  bool named = false;
  for (const auto& ev : s["events"]) named = named || ev["message"].get<std::string>().find("E-stop by view (viewer)") != std::string::npos;
  EXPECT_TRUE(named) << "the event names who pressed it";
  EXPECT_EQ(post("/api/bench/reset", "", "view").status, 403);
  EXPECT_EQ(post("/api/bench/enable", R"({"enabled": true})", "view").status, 403);
  EXPECT_EQ(post("/api/bench/setpoints", R"({"speed_rpm": 100})", "view").status, 403);
  const auto o = synbench::Json::parse(post("/api/bench/estop", "", "op").body);
  EXPECT_EQ(o["supervisor"]["trip"]["detail"], "E-stop by view (viewer)") << "latched: the first press is the trip";
}

TEST_F(Api, SetpointsAreValidatedNamingTheField) {
  auto bad = post("/api/bench/setpoints", R"({"speed_rpm": 9000})");
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(bad.body.find("speed_rpm"), std::string::npos);
  bad = post("/api/bench/setpoints", R"({"angle_deg": "x"})");
  EXPECT_NE(bad.body.find("angle_deg"), std::string::npos);
  bad = post("/api/bench/setpoints", R"({"speed": 100})");
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(bad.body.find("speed: unknown field"), std::string::npos);
  bad = post("/api/bench/setpoints", R"({"speed_rpm": )");
  EXPECT_EQ(bad.status, 400);
  EXPECT_NE(bad.body.find("bad_json"), std::string::npos);
  EXPECT_NE(bad.body.find("column"), std::string::npos);
}

std::string error_text(const Response& r) {
  const auto doc = synbench::Json::parse(r.body);
  return doc["error"]["code"].get<std::string>() + " " + doc["error"]["message"].get<std::string>();
}

TEST_F(Api, EveryBodyRouteRefusesABadBodyAtItsPointer) {
  const auto max_rpm = drivers::format_number(bench.description().max_speed_rpm);
  const std::pair<const char*, const char*> cases[][2] = {
      {{"/api/bench/enable", R"({"enabled": 1})"}, {"", "bad_field /enabled: must be true or false"}},
      {{"/api/bench/enable", R"({})"}, {"", "bad_field /enabled: required field is missing"}},
      {{"/api/bench/enable", R"({"enabled": true, "now": 1})"}, {"", "bad_field /now: unknown field (expected: enabled)"}},
      {{"/api/bench/mode", R"({"pwm": "svpwm"})"}, {"", "bad_field /pwm: must be one of capwm, aspwm (got 'svpwm')"}},
      {{"/api/bench/mode", R"({})"}, {"", "bad_field (document): give at least 1 of estimator, pwm"}},
      {{"/api/bench/setpoints", R"({"angle_deg": 90})"}, {"", "bad_field /angle_deg: 90 is outside (0, 90)"}},
      {{"/api/bench/setpoints", R"({"load_Nm": -1, "angle_deg": "x"})"},
       {"", "bad_field /load_Nm: -1 is outside [0, "}},
      {{"/api/bench/setpoints", R"({})"}, {"", "bad_field (document): give at least 1 of speed_rpm, load_Nm, angle_deg"}},
      {{"/api/bench/setpoints", R"(5)"}, {"", "bad_field (document): must be an object"}},
  };
  for (const auto& c : cases) {
    const auto r = post(c[0].first, c[0].second);
    EXPECT_EQ(r.status, 400) << c[0].first << " " << c[0].second;
    EXPECT_EQ(error_text(r).rfind(c[1].second, 0), 0u) << c[0].first << " " << c[0].second << ": " << error_text(r);
  }
  EXPECT_EQ(error_text(post("/api/bench/setpoints", R"({"speed_rpm": 1e6})")),
            "bad_field /speed_rpm: 1000000 is outside [0, " + max_rpm + "]");
  EXPECT_NE(error_text(post("/api/bench/setpoints", R"({"load_Nm": -1, "angle_deg": "x"})")).find("; /angle_deg: must be a number"),
            std::string::npos);
  // A refused body claims nothing: another operator may still take the lock.
  EXPECT_EQ(post("/api/bench/lock", "", "op2").status, 200);
  // Every route that reads a body publishes its schema.
  for (const auto& r : router.routes()) {
    if (r.pattern == "/api/bench/enable" || r.pattern == "/api/bench/mode" || r.pattern == "/api/bench/setpoints") {
      EXPECT_TRUE(r.request_schema) << r.pattern;
    }
  }
}

// The answers of the real handlers against the schemas the OpenAPI document publishes, with the
// bench idle and after an E-stop (trip, disable report filled in).
TEST_F(Api, LiveAnswersConformToThePublishedSchemas) {
  const auto doc = synbench::Json::parse(router.dispatch("GET", "/api/openapi.json", "", "").body);
  const auto check_all = [&](const std::string& when) {
    std::size_t checked = 0;
    for (const auto& [pattern, methods] : doc["paths"].items())
      for (const auto& [method, op] : methods.items()) {
        const auto& ok = op["responses"]["200"];
        if (!ok.contains("content")) continue;
        std::string upper = method;
        for (auto& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
        const auto answer = router.dispatch(upper, pattern, "Bearer op", "");
        ASSERT_EQ(answer.status, 200) << upper << " " << pattern << ": " << answer.body;
        const auto errors = validate(ok["content"]["application/json"]["schema"], synbench::Json::parse(answer.body));
        EXPECT_TRUE(errors.empty()) << when << ": " << upper << " " << pattern << ": " << to_string(errors);
        ++checked;
      }
    EXPECT_EQ(checked, 8u) << when;  // status, health, config, lock x3, whoami, estimators
  };
  check_all("idle");
  ASSERT_EQ(post("/api/bench/estop", "").status, 200);
  const auto status = synbench::Json::parse(router.dispatch("GET", "/api/bench/status", "Bearer view", "").body);
  EXPECT_FALSE(status["supervisor"]["disable"].is_null());
  check_all("after an E-stop");
}

// A drive that could not be read is null in the status with the read's error beside it (issue
// 37, item 6: a `synrm: null` once, while the drive ran, said nothing of why); a drive that was
// read has no error. Both forms conform to the published schema.
TEST(StatusJson, AnUnreadDriveSaysWhy) {
  BenchStatus s;
  s.load = drivers::LoadTelemetry{};
  s.synrm_error = "timeout (unit 1, input registers 0..21)";
  const auto j = status_json(s);
  EXPECT_TRUE(j["synrm"].is_null());
  EXPECT_EQ(j["synrm_error"], "timeout (unit 1, input registers 0..21)");
  EXPECT_FALSE(j["load"].is_null());
  EXPECT_TRUE(j["load_error"].is_null());
  const auto errors = validate(status_schema(), j);
  EXPECT_TRUE(errors.empty()) << to_string(errors);
}

// Every operation of the daemon's document has an operationId of its own (a generated client's
// method names; tests/api-tools/openapi_test.mjs calls them).
TEST_F(Api, OperationIdsAreUnique) {
  const auto doc = synbench::Json::parse(router.dispatch("GET", "/api/openapi.json", "", "").body);
  std::set<std::string> ids;
  std::size_t ops = 0;
  for (const auto& [path, methods] : doc["paths"].items())
    for (const auto& [method, op] : methods.items()) {
      ++ops;
      EXPECT_TRUE(ids.insert(op["operationId"].get<std::string>()).second) << op["operationId"] << " twice";
    }
  EXPECT_EQ(ids.size(), ops);
  EXPECT_TRUE(ids.count("getBenchStatus") && ids.count("postBenchEstop") && ids.count("deleteBenchLock"));
}

TEST_F(Api, TwinFollowsSpeedSetpointAndEstopLatches) {
  ASSERT_EQ(post("/api/bench/setpoints", R"({"speed_rpm": 300, "angle_deg": 50})").status, 200);
  ASSERT_EQ(post("/api/bench/enable", R"({"enabled": true})").status, 200);
  double speed = 0;
  for (int i = 0; i < 60 && std::abs(speed - 300) > 20; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    speed = synbench::Json::parse(router.dispatch("GET", "/api/bench/status", "Bearer view", "").body)["synrm"]["speed_rpm"];
  }
  EXPECT_NEAR(speed, 300, 20);
  const auto e = post("/api/bench/estop", "");
  ASSERT_EQ(e.status, 200);
  const auto s = synbench::Json::parse(e.body);
  EXPECT_EQ(s["supervisor"]["phase"], "estopped");
  EXPECT_EQ(post("/api/bench/enable", R"({"enabled": true})").status, 409);
  EXPECT_EQ(post("/api/bench/reset", "").status, 200);
}

// A user's disable is the ordered stop: the load torque comes off at the bench's ramp while the
// SynRM holds its speed, then the speed, then both drives (it used to zero both at once).
TEST_F(Api, DisableTakesTheLoadOffBeforeTheSpeed) {
  ASSERT_EQ(post("/api/bench/setpoints", R"({"speed_rpm": 500, "load_Nm": 1.5, "angle_deg": 50})").status, 200);
  ASSERT_EQ(post("/api/bench/enable", R"({"enabled": true})").status, 200);
  const auto status = [&] {
    return synbench::Json::parse(router.dispatch("GET", "/api/bench/status", "Bearer view", "").body);
  };
  synbench::Json st;
  for (int i = 0; i < 80; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    st = status();
    if (std::abs(st["synrm"]["speed_rpm"].get<double>() - 500) < 10 &&
        std::abs(st["load"]["torque_Nm"].get<double>() - 1.5) < 0.05 && i > 20)
      break;
  }
  ASSERT_NEAR(st["synrm"]["speed_rpm"].get<double>(), 500, 10);
  ASSERT_EQ(post("/api/bench/enable", R"({"enabled": false})").status, 200);
  double lowest_loaded_rpm = 1e9, load_gone_s = -1;
  bool stopped = false;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 200 && !stopped; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    st = status();
    const double torque = std::abs(st["load"]["torque_Nm"].get<double>());
    if (torque > 0.1) lowest_loaded_rpm = std::min(lowest_loaded_rpm, st["synrm"]["speed_rpm"].get<double>());
    if (torque < 0.05 && load_gone_s < 0)
      load_gone_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stopped = !st["stopping"].get<bool>() && !st["enabled"].get<bool>();
  }
  EXPECT_TRUE(stopped);
  EXPECT_GT(lowest_loaded_rpm, 450.0);
  EXPECT_GT(load_gone_s, 0.5);  // 1.5 N m at 2 N m/s
  EXPECT_LT(std::abs(st["synrm"]["speed_rpm"].get<double>()), 40.0);
}

TEST_F(Api, OneOperatorHoldsTheControlLockButAnyoneMayEstop) {
  ASSERT_EQ(post("/api/bench/setpoints", R"({"speed_rpm": 100})", "op").status, 200);
  const auto other = post("/api/bench/setpoints", R"({"speed_rpm": 200})", "op2");
  EXPECT_EQ(other.status, 409);
  EXPECT_NE(other.body.find("\"locked\""), std::string::npos);
  EXPECT_EQ(router.dispatch("DELETE", "/api/bench/lock", "Bearer op2", "").status, 409);
  EXPECT_EQ(post("/api/bench/estop", "", "op2").status, 200);
  EXPECT_EQ(router.dispatch("DELETE", "/api/bench/lock", "Bearer op", "").status, 200);
  EXPECT_EQ(post("/api/bench/lock", "", "op2").status, 200);
  EXPECT_EQ(post("/api/bench/reset", "", "op2").status, 200);
  EXPECT_EQ(post("/api/bench/reset", "", "op").status, 409);
}

TEST_F(Api, MetricsArePrometheusText) {
  auto m = router.dispatch("GET", "/metrics", "", "");
  // The drives' gauges once the bench has read them.
  for (int i = 0; i < 200 && m.body.find("synbench_load_torque_newton_meters") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    m = router.dispatch("GET", "/metrics", "", "");
  }
  EXPECT_EQ(m.status, 200);
  EXPECT_NE(m.body.find("# TYPE synbench_loop_ticks_total counter"), std::string::npos);
  // Every metric shown is in the table, with its help and type; base units spelled out.
  std::size_t shown = 0;
  for (const auto& spec : metric_specs()) {
    if (m.body.find(std::string("# TYPE ") + spec.name + " " + spec.type + "\n") == std::string::npos) continue;
    ++shown;
    EXPECT_NE(m.body.find(std::string("# HELP ") + spec.name + " " + spec.help + "\n"), std::string::npos) << spec.name;
  }
  EXPECT_GE(shown, 13u) << m.body;  // the twin's: all but the server's connection and WebSocket counts
  for (const char* abbreviated : {"_A ", "_V ", "_W ", "_C ", "_Nm ", "_rpm "})
    EXPECT_EQ(m.body.find(abbreviated), std::string::npos) << "a unit symbol in a metric name: " << abbreviated;
  const auto ticks = m.body.find("\nsynbench_loop_ticks_total ");
  ASSERT_NE(ticks, std::string::npos);
  const std::string value = m.body.substr(ticks + 27, m.body.find('\n', ticks + 1) - ticks - 27);
  EXPECT_EQ(value.find_first_not_of("0123456789"), std::string::npos) << "a counter is an integer: " << value;
}

TEST(GeneratedDocs, ApiDocHasTheMetricsTable) {
  test::expect_generated_section(std::string(SYNBENCH_SOURCE_DIR) + "/docs/api.md",
                                 "<!-- metrics: generated by metrics_table_markdown(), do not edit -->\n",
                                 "<!-- end of metrics -->", metrics_table_markdown());
}

}  // namespace
}  // namespace synbench::http
