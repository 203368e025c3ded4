// Router: matching, 404/405, bearer auth (401/403), handler errors, bodies checked against the
// route's request schema, the OpenAPI document.
#include "server/http/router.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

namespace synbench::http {
namespace {

Router make_router() {
  Router r([](std::string_view token) -> std::optional<Identity> {
    if (token == "op") return Identity{Role::operator_, "op"};
    if (token == "view") return Identity{Role::viewer, "view"};
    return std::nullopt;
  });
  r.add({"GET", "/api/open", Role::anyone, "open", [](const Request&) { return json_response(200, {{"ok", true}}); }});
  r.add({"GET", "/api/things/{id}", Role::viewer, "get a thing",
         [](const Request& q) { return json_response(200, {{"id", q.params.at("id")}, {"q", q.query.count("format") ? q.query.at("format") : ""}}); }});
  r.add({"POST", "/api/things/{id}/start", Role::operator_, "start a thing",
         [](const Request& q) { return json_response(200, {{"id", q.params.at("id")}, {"role", role_name(q.caller)}}); }});
  r.add({"POST", "/api/boom", Role::operator_, "throws", [](const Request&) -> Response { throw std::runtime_error("kaput"); }});
  r.add({"POST", "/api/async-boom", Role::operator_, "throws before answering",
         AsyncHandler([](const Request&, Reply) { throw std::runtime_error("kaput \xFF"); })});
  r.add({"GET", "/api/echo", Role::anyone, "echoes bytes into JSON",
         [](const Request&) { return json_response(200, {{"text", std::string("a\xFF" "b")}}); }});
  // The handler answers with the parsed body it was given.
  r.add({"POST", "/api/things", Role::operator_, "takes a body",
         [](const Request& q) { return json_response(200, {{"got", q.json}}); },
         synbench::Json{{"type", "object"},
                        {"required", synbench::Json::array({"n"})},
                        {"additionalProperties", false},
                        {"properties", {{"n", {{"type", "integer"}, {"minimum", 1}, {"maximum", 9}}}, {"a/b", {{"type", "string"}}}}}}});
  Route plan{"POST", "/api/plans", Role::viewer, "a body whose own error code is bad_plan",
             [](const Request&) { return json_response(200, {{"ok", true}}); }, synbench::Json{{"type", "object"}}};
  plan.body_error_code = "bad_plan";
  r.add(std::move(plan));
  return r;
}

synbench::Json body(const Response& r) { return synbench::Json::parse(r.body); }

TEST(Router, MatchesPatternsAndDecodesQuery) {
  const Router r = make_router();
  const auto res = r.dispatch("GET", "/api/things/42?format=csv&x=a%20b", "Bearer view", "");
  ASSERT_EQ(res.status, 200);
  EXPECT_EQ(body(res)["id"], "42");
  EXPECT_EQ(body(res)["q"], "csv");
  EXPECT_EQ(parse_query("a=1&b=x%20y&c")["b"], "x y");
}

TEST(Router, UnknownPathIs404AndWrongMethod405WithAllow) {
  const Router r = make_router();
  const auto nf = r.dispatch("GET", "/api/nothing", "", "");
  EXPECT_EQ(nf.status, 404);
  EXPECT_EQ(body(nf)["error"]["code"], "not_found");
  const auto na = r.dispatch("DELETE", "/api/open", "", "");
  EXPECT_EQ(na.status, 405);
  ASSERT_EQ(na.headers.size(), 1u);
  EXPECT_EQ(na.headers[0].second, "GET");
}

TEST(Router, AuthIs401WithoutOrWithBadTokenAnd403ForLowRole) {
  const Router r = make_router();
  EXPECT_EQ(r.dispatch("GET", "/api/open", "", "").status, 200);
  const auto none = r.dispatch("POST", "/api/things/1/start", "", "");
  EXPECT_EQ(none.status, 401);
  EXPECT_EQ(body(none)["error"]["code"], "unauthorized");
  EXPECT_EQ(r.dispatch("POST", "/api/things/1/start", "Bearer nope", "").status, 401);
  EXPECT_EQ(r.dispatch("POST", "/api/things/1/start", "Basic op", "").status, 401);
  const auto viewer = r.dispatch("POST", "/api/things/1/start", "Bearer view", "");
  EXPECT_EQ(viewer.status, 403);
  EXPECT_EQ(body(viewer)["error"]["code"], "forbidden");
  const auto op = r.dispatch("POST", "/api/things/1/start", "bearer op", "");
  EXPECT_EQ(op.status, 200);
  EXPECT_EQ(body(op)["role"], "operator");
  // An operator may read.
  EXPECT_EQ(r.dispatch("GET", "/api/things/1", "Bearer op", "").status, 200);
}

TEST(Router, MessagesNeverContainTheToken) {
  const Router r = make_router();
  const auto res = r.dispatch("POST", "/api/things/1/start", "Bearer secret-token-value", "");
  EXPECT_EQ(res.body.find("secret-token-value"), std::string::npos);
}

TEST(Router, HandlerExceptionIs500JsonError) {
  const Router r = make_router();
  const auto res = r.dispatch("POST", "/api/boom", "Bearer op", "");
  EXPECT_EQ(res.status, 500);
  EXPECT_EQ(body(res)["error"]["code"], "internal");
}

TEST(Router, AnAsyncHandlerThatThrowsIsOne500) {
  const Router r = make_router();
  const auto res = r.dispatch("POST", "/api/async-boom", "Bearer op", "");
  EXPECT_EQ(res.status, 500);
  EXPECT_NE(body(res)["error"]["message"].get<std::string>().find("kaput \\xFF"), std::string::npos) << res.body;
}

// Bytes that are not UTF-8, in the path, a path parameter, the query or a handler's own JSON:
// always a valid JSON answer, a 400 naming the parameter where one is to blame.
TEST(Router, BytesThatAreNotUtf8NeverBreakTheAnswer) {
  const Router r = make_router();
  const auto path = r.dispatch("GET", "/api/\xFF", "", "");
  EXPECT_EQ(path.status, 404);
  EXPECT_EQ(body(path)["error"]["message"], "no route for /api/\\xFF");
  const auto param = r.dispatch("GET", "/api/things/%ff", "Bearer view", "");
  EXPECT_EQ(param.status, 400);
  EXPECT_EQ(body(param)["error"]["message"], "id: not valid UTF-8");
  const auto raw_param = r.dispatch("GET", "/api/things/\xC3", "Bearer view", "");
  EXPECT_EQ(raw_param.status, 400);
  const auto query = r.dispatch("GET", "/api/things/1?format=%C3%28", "Bearer view", "");
  EXPECT_EQ(query.status, 400);
  EXPECT_EQ(body(query)["error"]["message"], "format: not valid UTF-8");
  const auto name = r.dispatch("GET", "/api/things/1?%ff=1", "Bearer view", "");
  EXPECT_EQ(name.status, 400);
  EXPECT_EQ(body(name)["error"]["code"], "bad_field");
  const auto echo = r.dispatch("GET", "/api/echo", "", "");
  EXPECT_EQ(echo.status, 200);
  EXPECT_EQ(body(echo)["text"], "a\xEF\xBF\xBD" "b");  // U+FFFD
  // The 404 and 401 come before the parameter check: no route, no token, no judgement.
  EXPECT_EQ(r.dispatch("GET", "/api/things/%ff", "", "").status, 401);
}

TEST(Router, BodiesAreCheckedAgainstTheRequestSchemaBeforeTheHandler) {
  const Router r = make_router();
  const auto ok = r.dispatch("POST", "/api/things", "Bearer op", R"({"n": 3})");
  ASSERT_EQ(ok.status, 200) << ok.body;
  EXPECT_EQ(body(ok)["got"]["n"], 3);
  const auto message = [&](const std::string& text) {
    const auto res = r.dispatch("POST", "/api/things", "Bearer op", text);
    EXPECT_EQ(res.status, 400) << text;
    return body(res)["error"]["code"].get<std::string>() + " " + body(res)["error"]["message"].get<std::string>();
  };
  EXPECT_EQ(message(R"({"n": 10})"), "bad_field /n: 10 is outside [1, 9]");
  EXPECT_EQ(message(R"({"n": "3"})"), "bad_field /n: must be an integer");
  EXPECT_EQ(message(R"({})"), "bad_field /n: required field is missing");
  EXPECT_EQ(message(R"({"n": 1, "a/b": 2, "x": 0})"),
            "bad_field /a~1b: must be a string; /x: unknown field (expected: n, a/b)");
  EXPECT_EQ(message(R"([1])"), "bad_field (document): must be an object");
  EXPECT_EQ(message(""), "bad_json the request needs a JSON body");
  EXPECT_NE(message(R"({"n": )").find("bad_json the body is not valid JSON"), std::string::npos);
  EXPECT_NE(message("{\"n\": \"\xFF\"}").find("bad_json the body is not valid UTF-8"), std::string::npos);
  // A route's own code for a body it refuses.
  const auto plan = r.dispatch("POST", "/api/plans", "Bearer view", "3");
  EXPECT_EQ(plan.status, 400);
  EXPECT_EQ(body(plan)["error"]["code"], "bad_plan");
  // Auth first: a caller without the role learns nothing about the body.
  EXPECT_EQ(r.dispatch("POST", "/api/things", "", "nonsense").status, 401);
  EXPECT_EQ(r.dispatch("POST", "/api/things", "Bearer view", "nonsense").status, 403);
}

TEST(Router, ARouteWhoseSchemaUsesAnUnknownKeywordIsRefused) {
  Router r([](std::string_view) { return std::nullopt; });
  const auto handler = [](const Request&) { return json_response(200, synbench::Json::object()); };
  EXPECT_THROW(r.add({"POST", "/x", Role::anyone, "x", handler, synbench::Json{{"type", "object"}, {"patternProperties", {}}}}),
               std::invalid_argument);
  Route answer{"GET", "/y", Role::anyone, "y", handler};
  answer.response_schema = synbench::Json{{"type", "string"}, {"format", "date-time"}};
  try {
    r.add(std::move(answer));
    ADD_FAILURE() << "a response schema with format was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("GET /y: the response schema: /format: keyword not implemented"), std::string::npos) << e.what();
  }
  // Only Worker::offloaded may leave the body check to the handler (it runs it on the worker).
  Route unchecked{"POST", "/z", Role::anyone, "z", handler, synbench::Json{{"type", "object"}}};
  unchecked.body_checked_by_handler = true;
  EXPECT_THROW(r.add(std::move(unchecked)), std::invalid_argument);
  EXPECT_TRUE(r.routes().empty());
}

TEST(Router, OpenApiListsEveryRouteWithRoleAndPathParameters) {
  const Router r = make_router();
  const auto doc = r.openapi("t", "1");
  EXPECT_EQ(doc["openapi"], "3.0.3");
  std::size_t ops = 0;
  for (const auto& [path, methods] : doc["paths"].items()) ops += methods.size();
  EXPECT_EQ(ops, r.routes().size());
  const auto& start = doc["paths"]["/api/things/{id}/start"]["post"];
  EXPECT_EQ(start["x-synbench-role"], "operator");
  EXPECT_EQ(start["parameters"][0]["name"], "id");
  EXPECT_TRUE(start["responses"].contains("401"));
  EXPECT_TRUE(doc["paths"]["/api/open"]["get"]["security"].empty());
  // Readable, URL-safe operationIds a client generator turns into method names.
  EXPECT_EQ(start["operationId"], "postThingStart");
  EXPECT_EQ(operation_id("GET", "/api/bench/status"), "getBenchStatus");
  EXPECT_EQ(operation_id("GET", "/api/sweeps/{id}/points"), "getSweepPoints");
  EXPECT_EQ(operation_id("GET", "/api/sweeps/{id}/report.csv"), "getSweepReportCsv");
  EXPECT_EQ(operation_id("DELETE", "/api/bench/lock"), "deleteBenchLock");
  EXPECT_EQ(operation_id("GET", "/metrics"), "getMetrics");
  EXPECT_EQ(doc["servers"][0]["url"], "/");
  for (const auto& [path, methods] : doc["paths"].items())
    for (const auto& [method, op] : methods.items()) {
      EXPECT_TRUE(op["responses"].contains("400") && op["responses"].contains("403")) << method << " " << path;
      const std::string id = op["operationId"];
      EXPECT_EQ(id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"), std::string::npos) << id;
    }
  // The published request schema is the one the router checks.
  EXPECT_EQ(doc["paths"]["/api/things"]["post"]["requestBody"]["content"]["application/json"]["schema"],
            r.routes()[6].request_schema.value());
}

}  // namespace
}  // namespace synbench::http
