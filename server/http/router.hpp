// The daemon's REST surface as data: a route table (method, path pattern with {name} segments,
// required role, OpenAPI summary, handler) and a pure dispatcher. Handlers are functions of the
// request (their context captured when the table is built); nothing here touches a socket, so
// routing, auth and the OpenAPI document are unit-tested without a server. A handler either
// answers at once, or (a bench command) hands a Reply to the bench thread and answers when the
// bench has acted: the io thread never waits for a device.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/json.hpp"

namespace synbench::http {

// What a caller may do. `anyone` needs no token; `viewer` reads; `operator_` commands the bench.
enum class Role { anyone = 0, viewer = 1, operator_ = 2 };
const char* role_name(Role r);
std::optional<Role> parse_role(std::string_view name);  // "viewer" or "operator"

struct Request {
  std::string method;                         // "GET", "POST", ...
  std::string path;                           // without the query
  std::map<std::string, std::string> query;   // decoded ?a=b&c=d
  std::map<std::string, std::string> params;  // {name} segments of the matched pattern
  std::string body;
  // The body parsed, once it has passed the route's request_schema (null for a route without one).
  synbench::Json json;
  Role caller = Role::anyone;                 // the authenticated role, set by the dispatcher
  std::string caller_id;                      // who: a label of the token (never the token), or ""
};

struct Response {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra headers (Allow, ...)
};

// Serialises `j`, writing any string that is not UTF-8 with U+FFFD instead of throwing: every
// JSON the daemon sends goes through here, as request-derived text can hold any byte.
std::string dump_json(const synbench::Json& j);
Response json_response(int status, const synbench::Json& body);
// {"error": {"code": code, "message": message}}
Response error_response(int status, const std::string& code, const std::string& message);
// Runs `make`; an exception it throws becomes a 500 `internal` answer and a line on stderr
// naming `what`. For handlers and the bench thread's answers: nothing may escape into the io
// loop or the bench thread.
Response guarded(const char* what, const std::function<Response()>& make);

using Handler = std::function<Response(const Request&)>;
// Called exactly once, on any thread.
using Reply = std::function<void(Response)>;
using AsyncHandler = std::function<void(const Request&, Reply)>;

struct Route {
  Route(std::string m, std::string p, Role r, std::string s, Handler h, std::optional<synbench::Json> schema = std::nullopt)
      : method(std::move(m)), pattern(std::move(p)), role(r), summary(std::move(s)), handler(std::move(h)),
        request_schema(std::move(schema)) {}
  Route(std::string m, std::string p, Role r, std::string s, AsyncHandler h, std::optional<synbench::Json> schema = std::nullopt)
      : method(std::move(m)), pattern(std::move(p)), role(r), summary(std::move(s)), async_handler(std::move(h)),
        request_schema(std::move(schema)) {}
  std::string method;
  std::string pattern;  // "/api/sweeps/{id}/start"
  Role role = Role::viewer;
  std::string summary;  // one line, for the OpenAPI document and docs/api.md
  Handler handler;             // one of the two
  AsyncHandler async_handler;
  // JSON Schema of the body, if it takes one: the router refuses a body that does not conform
  // (json_schema.hpp) before the handler runs, with `body_error_code`.
  std::optional<synbench::Json> request_schema;
  std::string body_error_code = "bad_field";
  // Set by Worker::offloaded: the handler runs check_body itself on the worker thread, so
  // that the io thread never parses a heavy route's (up to 64 KiB) body. Also set by a route
  // whose body is optional (the sweep abort's reason): it checks a body only when one is given.
  bool body_checked_by_handler = false;
  std::optional<synbench::Json> response_schema;  // JSON Schema of the 200 answer, where the OpenAPI document gives one
  std::string response_content_type = "application/json";  // of the 200 answer, for the OpenAPI document
};

// A token's role and a label naming its holder in messages and the control lock (the first
// digits of the token's digest: never the token).
struct Identity {
  Role role = Role::viewer;
  std::string id;
};
// Maps a bearer token to its identity; nullopt for an unknown token.
using Authenticator = std::function<std::optional<Identity>(std::string_view token)>;

class Router {
 public:
  explicit Router(Authenticator auth) : auth_(std::move(auth)) {}
  // Throws std::invalid_argument when a schema of the route uses a keyword the validator does
  // not implement: what is published must be what is checked.
  void add(Route route);
  const std::vector<Route>& routes() const { return routes_; }

  // `target` is the request-target ("/api/x?y=z"); `authorization` the Authorization header
  // (empty when absent). 404 unknown path, 405 wrong method, 401 no or unknown token, 403 role
  // too low; 400 `bad_field` for a path parameter or query parameter that is not UTF-8 after
  // percent-decoding; 400 `bad_json` for a body that is not JSON, and the route's
  // body_error_code for one that fails its request_schema (every problem at its pointer); otherwise the handler's response, given to `reply` (at once, or from the
  // bench thread). Never throws: a handler's exception is a 500, logged on stderr.
  void dispatch_async(const std::string& method, const std::string& target, std::string_view authorization,
                      std::string body, Reply reply) const;
  // The same, waiting for the answer: for tests and tools, never on the io thread.
  Response dispatch(const std::string& method, const std::string& target,
                    std::string_view authorization, std::string body) const;

  // Who an Authorization header ("Bearer TOKEN") names; nullopt for none or an unknown token.
  std::optional<Identity> identify(std::string_view authorization) const;

  // OpenAPI 3.0 document generated from the table.
  synbench::Json openapi(const std::string& title, const std::string& version) const;

 private:
  // dispatch_async's body; may throw, which dispatch_async turns into a 500.
  void route_and_call(const std::string& method, const std::string& target, std::string_view authorization,
                      std::string body, const Reply& reply) const;
  Authenticator auth_;
  std::vector<Route> routes_;
};

// `req.body` against a route's request schema: parsed into req.json, or the 400 saying why not
// (`bad_json` for a missing body or one that is not JSON, else `error_code` listing every
// problem at its JSON pointer).
std::optional<Response> check_body(const synbench::Json& schema, const std::string& error_code, Request& req);

// Splits "?a=1&b=x%20y" into decoded pairs; exposed for tests.
std::map<std::string, std::string> parse_query(std::string_view query);
// True when `path` matches `pattern`; fills `params` with the {name} segments.
bool match_pattern(std::string_view pattern, std::string_view path, std::map<std::string, std::string>& params);
// The OpenAPI operationId of a route: "getBenchStatus" for GET /api/bench/status,
// "getSweepPoints" for GET /api/sweeps/{id}/points.
std::string operation_id(const std::string& method, const std::string& pattern);

}  // namespace synbench::http
