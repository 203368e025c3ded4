// Route matching, bearer auth and the OpenAPI document of the route table.
#include "server/http/router.hpp"

#include <algorithm>
#include <cctype>
#include <atomic>
#include <exception>
#include <future>
#include <iostream>
#include <memory>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "drivers/json_file.hpp"
#include "drivers/utf8.hpp"
#include "server/http/json_schema.hpp"
#include "server/http/url_text.hpp"

namespace synbench::http {

const char* role_name(Role r) {
  switch (r) {
    case Role::anyone: return "anyone";
    case Role::viewer: return "viewer";
    case Role::operator_: return "operator";
  }
  return "?";
}

std::optional<Role> parse_role(std::string_view name) {
  if (name == "viewer") return Role::viewer;
  if (name == "operator") return Role::operator_;
  return std::nullopt;
}

std::string dump_json(const synbench::Json& j) {
  return j.dump(-1, ' ', false, synbench::Json::error_handler_t::replace);
}

Response json_response(int status, const synbench::Json& body) {
  Response r;
  r.status = status;
  r.body = dump_json(body);
  return r;
}

Response guarded(const char* what, const std::function<Response()>& make) {
  std::string why;
  try {
    return make();
  } catch (const std::exception& e) {
    why = drivers::escape_invalid_utf8(e.what());
  } catch (...) {
    why = "an exception that is not a std::exception";
  }
  std::cerr << "synbench serve: internal error in " << drivers::escape_invalid_utf8(what) << ": " << why << "\n";
  return error_response(500, "internal", "the request failed inside the daemon: " + why);
}

Response error_response(int status, const std::string& code, const std::string& message) {
  return json_response(status, {{"error", {{"code", code}, {"message", message}}}});
}

namespace {

std::vector<std::string_view> segments(std::string_view path) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i <= path.size()) {
    const std::size_t j = path.find('/', i);
    const std::size_t end = j == std::string_view::npos ? path.size() : j;
    if (end > i) out.push_back(path.substr(i, end - i));
    if (j == std::string_view::npos) break;
    i = j + 1;
  }
  return out;
}

// A malformed escape leaves the text as sent: the parameter's own check then refuses it.
std::string decode(std::string_view s) { return percent_decode(s, Plus::space).value_or(std::string(s)); }

}  // namespace

std::map<std::string, std::string> parse_query(std::string_view query) {
  std::map<std::string, std::string> out;
  std::size_t i = 0;
  while (i < query.size()) {
    std::size_t amp = query.find('&', i);
    if (amp == std::string_view::npos) amp = query.size();
    const std::string_view pair = query.substr(i, amp - i);
    if (!pair.empty()) {
      const std::size_t eq = pair.find('=');
      if (eq == std::string_view::npos) out[decode(pair)] = "";
      else out[decode(pair.substr(0, eq))] = decode(pair.substr(eq + 1));
    }
    i = amp + 1;
  }
  return out;
}

namespace {

// The next non-empty '/'-separated segment of `s` from `pos` into `seg`; false at the end.
bool next_segment(std::string_view s, std::size_t& pos, std::string_view& seg) {
  while (pos < s.size() && s[pos] == '/') ++pos;
  if (pos >= s.size()) return false;
  const std::size_t end = std::min(s.find('/', pos), s.size());
  seg = s.substr(pos, end - pos);
  pos = end;
  return true;
}

}  // namespace

// Walks both strings segment by segment: every request tries the routes in turn, and a route
// that does not match costs no allocation.
bool match_pattern(std::string_view pattern, std::string_view path, std::map<std::string, std::string>& params) {
  std::size_t pi = 0, si = 0;
  std::string_view p, s;
  std::map<std::string, std::string> found;
  for (;;) {
    const bool more_p = next_segment(pattern, pi, p), more_s = next_segment(path, si, s);
    if (more_p != more_s) return false;
    if (!more_p) break;
    if (p.size() > 2 && p.front() == '{' && p.back() == '}') found[std::string(p.substr(1, p.size() - 2))] = decode(s);
    else if (p != s) return false;
  }
  params = std::move(found);
  return true;
}

void Router::add(Route route) {
  if (route.body_checked_by_handler && !route.async_handler)
    throw std::invalid_argument(route.method + " " + route.pattern + ": a body checked by the handler needs Worker::offloaded");
  for (const auto* schema : {&route.request_schema, &route.response_schema}) {
    if (!*schema) continue;
    if (const auto problems = check_schema(**schema); !problems.empty())
      throw std::invalid_argument(route.method + " " + route.pattern + ": the " +
                                  (schema == &route.request_schema ? "request" : "response") + " schema: " + to_string(problems));
  }
  routes_.push_back(std::move(route));
}

std::optional<Identity> Router::identify(std::string_view authorization) const {
  const std::size_t sp = authorization.find(' ');
  if (sp == std::string_view::npos || ascii_lower(authorization.substr(0, sp)) != "bearer" || !auth_) return std::nullopt;
  std::string_view token = authorization.substr(sp + 1);
  while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
  return auth_(token);
}

Response Router::dispatch(const std::string& method, const std::string& target, std::string_view authorization,
                          std::string body) const {
  auto answer = std::make_shared<std::promise<Response>>();
  auto future = answer->get_future();
  dispatch_async(method, target, authorization, std::move(body), [answer](Response r) { answer->set_value(std::move(r)); });
  return future.get();
}

namespace {

// The first path or query parameter that is not UTF-8 once percent-decoded, as a 400 naming it:
// handlers and their messages may then treat every parameter as text.
std::optional<Response> non_utf8_parameter(const Request& req) {
  for (const auto& [name, value] : req.params)
    if (!drivers::is_valid_utf8(value)) return error_response(400, "bad_field", name + ": not valid UTF-8");
  for (const auto& [name, value] : req.query) {
    if (!drivers::is_valid_utf8(name))
      return error_response(400, "bad_field", "query: the parameter name '" + drivers::escape_invalid_utf8(name) + "' is not valid UTF-8");
    if (!drivers::is_valid_utf8(value)) return error_response(400, "bad_field", name + ": not valid UTF-8");
  }
  return std::nullopt;
}

}  // namespace

std::optional<Response> check_body(const synbench::Json& schema, const std::string& error_code, Request& req) {
  if (req.body.empty()) return error_response(400, "bad_json", "the request needs a JSON body");
  // The shared reader: "the body is not valid UTF-8 at byte 12", "the body is nested deeper
  // than 64 levels at byte 64", "the body is not valid JSON: parse error at line 1, column 9:
  // ...", a number out of double's range (1e999) included.
  drivers::JsonParsed parsed = drivers::parse_json_text(req.body);
  if (!parsed.ok()) return error_response(400, "bad_json", "the body is " + parsed.error);
  if (const auto errors = validate(schema, parsed.doc); !errors.empty())
    return error_response(400, error_code, to_string(errors));
  req.json = std::move(parsed.doc);
  return std::nullopt;
}

void Router::dispatch_async(const std::string& method, const std::string& target, std::string_view authorization,
                            std::string body, Reply reply) const {
  // Shared with the handler, which may answer from the bench thread: whichever side answers
  // first (the handler, or the exception it threw here) is the one answer.
  struct Once {
    std::atomic<bool> used{false};
    Reply reply;
    void operator()(Response r) {
      if (!used.exchange(true)) reply(std::move(r));
    }
  };
  auto once = std::make_shared<Once>();
  once->reply = std::move(reply);
  // Nothing thrown here may reach the io loop: routing, the token check and the handler are all
  // inside, and an exception becomes the one 500 answer.
  const auto failed = [&](const std::string& why) {
    std::cerr << "synbench serve: internal error in " << drivers::escape_invalid_utf8(method + " " + target.substr(0, target.find('?')))
              << ": " << why << "\n";
    (*once)(error_response(500, "internal", "the request failed inside the daemon: " + why));
  };
  try {
    route_and_call(method, target, authorization, std::move(body), [once](Response r) { (*once)(std::move(r)); });
  } catch (const std::exception& e) {
    failed(drivers::escape_invalid_utf8(e.what()));
  } catch (...) {
    failed("an exception that is not a std::exception");
  }
}

void Router::route_and_call(const std::string& method, const std::string& target, std::string_view authorization,
                            std::string body, const Reply& reply) const {
  Request req;
  req.method = method;
  const std::size_t q = target.find('?');
  req.path = target.substr(0, q);
  if (q != std::string::npos) req.query = parse_query(std::string_view(target).substr(q + 1));
  req.body = std::move(body);
  // The path is echoed in messages (only those); a byte that is not UTF-8 is shown as \xNN.
  const auto shown_path = [&req] { return drivers::escape_invalid_utf8(req.path); };

  const Route* route = nullptr;
  std::set<std::string> allowed;
  for (const Route& r : routes_) {
    std::map<std::string, std::string> params;
    if (!match_pattern(r.pattern, req.path, params)) continue;
    allowed.insert(r.method);
    // HEAD is answered like GET (the session drops the body).
    if (r.method == method || (method == "HEAD" && r.method == "GET")) {
      route = &r;
      req.params = std::move(params);
      break;
    }
  }
  if (!route) {
    if (allowed.empty()) return reply(error_response(404, "not_found", "no route for " + shown_path()));
    std::string allow;
    for (const auto& m : allowed) allow += (allow.empty() ? "" : ", ") + m;
    Response r = error_response(405, "method_not_allowed",
                                drivers::escape_invalid_utf8(method) + " is not allowed on " + shown_path() + " (allowed: " + allow + ")");
    r.headers.emplace_back("Allow", allow);
    return reply(std::move(r));
  }

  // The token is checked whenever one is given, so a bad token is reported even on open routes
  // only when they need one; the token itself never appears in a message.
  const bool token_given = !authorization.empty();
  const std::optional<Identity> caller = identify(authorization);
  if (route->role != Role::anyone) {
    auto challenge = [](Response r) {
      r.headers.emplace_back("WWW-Authenticate", "Bearer realm=\"synbench\"");
      return r;
    };
    if (!token_given) return reply(challenge(error_response(401, "unauthorized", "this route needs a bearer token (Authorization: Bearer TOKEN)")));
    if (!caller) return reply(challenge(error_response(401, "unauthorized", "the bearer token is not valid")));
    if (static_cast<int>(caller->role) < static_cast<int>(route->role))
      return reply(error_response(403, "forbidden", std::string("this route needs the ") + role_name(route->role) +
                                                        " role; the token has " + role_name(caller->role)));
  }
  if (caller) {
    req.caller = caller->role;
    req.caller_id = caller->id;
  }
  if (auto bad = non_utf8_parameter(req)) return reply(std::move(*bad));
  if (route->request_schema && !route->body_checked_by_handler)
    if (auto bad = check_body(*route->request_schema, route->body_error_code, req)) return reply(std::move(*bad));
  if (route->async_handler) return route->async_handler(req, reply);
  reply(route->handler(req));
}

// A client generator's method name: the method, then the path's words in camel case, "api"
// left out; a path parameter makes the word before it singular ("getSweepPoints" for GET
// /api/sweeps/{id}/points, "getBenchStatus", "getOpenapiJson"). URL-safe and unique per route.
std::string operation_id(const std::string& method, const std::string& pattern) {
  std::string id = ascii_lower(method);
  std::vector<std::string> words;
  for (const auto seg : segments(pattern)) {
    if (seg.size() > 2 && seg.front() == '{') {
      if (!words.empty() && words.back().size() > 3 && words.back().back() == 's') words.back().pop_back();
      continue;
    }
    if (words.empty() && seg == "api") continue;
    std::string word;
    bool upper = true;
    for (const char ch : seg) {
      if (ch == '-' || ch == '_' || ch == '.') {
        upper = true;
        continue;
      }
      const auto c = static_cast<unsigned char>(ch);
      word += static_cast<char>(upper ? std::toupper(c) : std::tolower(c));
      upper = false;
    }
    words.push_back(word);
  }
  for (const auto& w : words) id += w;
  return id;
}

synbench::Json Router::openapi(const std::string& title, const std::string& version) const {
  synbench::Json paths = synbench::Json::object();
  for (const Route& r : routes_) {
    synbench::Json op;
    op["summary"] = r.summary;
    op["operationId"] = operation_id(r.method, r.pattern);
    op["x-synbench-role"] = role_name(r.role);
    if (r.role != Role::anyone) op["security"] = synbench::Json::array({{{"bearer", synbench::Json::array()}}});
    else op["security"] = synbench::Json::array();
    synbench::Json params = synbench::Json::array();
    for (auto seg : segments(r.pattern))
      if (seg.size() > 2 && seg.front() == '{')
        params.push_back({{"name", std::string(seg.substr(1, seg.size() - 2))}, {"in", "path"}, {"required", true},
                          {"schema", {{"type", "string"}}}});
    if (!params.empty()) op["parameters"] = params;
    if (r.request_schema)
      op["requestBody"] = {{"required", true}, {"content", {{"application/json", {{"schema", *r.request_schema}}}}}};
    synbench::Json ok = {{"description", "success"}};
    if (r.response_schema) ok["content"] = {{r.response_content_type, {{"schema", *r.response_schema}}}};
    synbench::Json responses = {{"200", ok},
                                {"default", {{"description", "error"},
                                             {"content", {{"application/json", {{"schema", {{"$ref", "#/components/schemas/Error"}}}}}}}}}};
    // Every route can be refused: a Host header that does not name the daemon (403), a request
    // that is not well-formed HTTP (400); a route with a role, a missing or invalid token (401).
    responses["400"] = {{"description", "a malformed request or body, the field named in the error"}};
    if (r.role != Role::anyone) {
      responses["401"] = {{"description", "no or invalid bearer token"}};
      responses["403"] = {{"description", std::string("the token's role is below ") + role_name(r.role) +
                                              ", or the Host header does not name the daemon"}};
    } else {
      responses["403"] = {{"description", "the Host header does not name the daemon"}};
    }
    op["responses"] = responses;
    paths[r.pattern][ascii_lower(r.method)] = op;
  }
  return {
      {"openapi", "3.0.3"},
      {"info", {{"title", title}, {"version", version},
                {"description", "The REST API of the synbench daemon (docs/api.md): the bench, its sweeps and their results."}}},
      // Relative: the daemon that served the document (behind a proxy, under its address).
      {"servers", synbench::Json::array({{{"url", "/"}, {"description", "the daemon that served this document"}}})},
      {"paths", paths},
      {"components",
       {{"securitySchemes", {{"bearer", {{"type", "http"}, {"scheme", "bearer"}}}}},
        {"schemas",
         {{"Error",
           {{"type", "object"},
            {"required", {"error"}},
            {"properties",
             {{"error",
               {{"type", "object"},
                {"required", {"code", "message"}},
                {"properties", {{"code", {{"type", "string"}}}, {"message", {{"type", "string"}}}}}}}}}}}}}}},
  };
}

}  // namespace synbench::http
