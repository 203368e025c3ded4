// Router: matching, 404/405, bearer auth (401/403), handler errors, the OpenAPI document.
#include "server/http/router.hpp"

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
}

}  // namespace
}  // namespace synbench::http
