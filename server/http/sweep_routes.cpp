// POST /api/sweeps; GET /api/sweeps, /api/sweeps/{id}, /api/sweeps/{id}/points; see sweep_routes.hpp, docs/api.md.
#include "server/http/sweep_routes.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <limits>
#include <map>
#include <span>
#include <string>

#include "app/report/sweep_report.hpp"
#include "bench/analysis.hpp"
#include "bench/sweep_outcome.hpp"
#include "bench/sweep_plan.hpp"
#include "bench/sweep_plan_bench_limits.hpp"
#include "bench/sweep_presets.hpp"
#include "bench/window_plausibility.hpp"
#include "db/export.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/response_schemas.hpp"

namespace synbench::http {
namespace {

template <class T>
synbench::Json optional_json(const std::optional<T>& v) {
  return v ? synbench::Json(*v) : synbench::Json(nullptr);
}

synbench::Json sweep_json(const db::Sweep& s, bool with_plan) {
  synbench::Json j = {{"id", s.id},
                      {"name", s.meta.name},
                      {"state", std::string(db::name(s.state))},
                      {"total_points", s.meta.total_points},
                      {"points_stored", s.points_stored},
                      {"created_at", s.created_at},
                      {"started_at", optional_json(s.started_at)},
                      {"finished_at", optional_json(s.finished_at)},
                      {"last_error", optional_json(s.last_error)},
                      {"software_version", s.meta.software_version}};
  // The bench the sweep ran on (docs/database.md "Bench identity"): "" on sweeps from before.
  synbench::Json devices = synbench::Json::array();
  for (const auto& d : s.meta.devices)
    devices.push_back({{"device", d.device}, {"profile", d.profile}, {"version", d.version}});
  j["bench"] = {{"name", s.meta.bench_name}, {"host", s.meta.bench_host}, {"devices", std::move(devices)}};
  j["key"] = optional_json(s.meta.key);
  if (with_plan) j["plan"] = s.meta.plan;
  return j;
}

// The {id} segment as a positive integer, or a 400 naming it.
std::optional<std::int64_t> sweep_id(const Request& req, Response& error) {
  const std::string& text = req.params.at("id");
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || v <= 0) {
    error = error_response(400, "bad_field", "id: '" + text + "' is not a sweep id (a positive integer)");
    return std::nullopt;
  }
  return v;
}

// Every problem of a plan, each at its JSON pointer, as one 400.
Response bad_plan(const bench::SweepPlanParseResult& plan) {
  std::string message;
  for (const auto& e : plan.errors) message += (message.empty() ? "" : "; ") + bench::to_string(e);
  return error_response(400, "bad_plan", message.empty() ? "the plan does not parse" : message);
}

// A plan that parses but does not fit this bench (a speed above its drive's limit): as one 400,
// every problem at its pointer, so create and estimate refuse what start would fault at.
std::optional<Response> bad_for_bench(const synbench::Json& doc, const bench::SweepPlan& plan,
                                      const bench::BenchSetpointLimits& limits) {
  const bool from_preset = doc.is_object() && doc.contains("preset") && !doc.contains("dimensions");
  const auto errors = bench::check_bench_limits(plan, limits, from_preset);
  if (errors.empty()) return std::nullopt;
  return bad_plan({std::nullopt, errors});
}

// "encoder/capwm" -> a configuration, for ?reference=.
std::optional<bench::Configuration> parse_configuration_label(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return std::nullopt;
  const auto e = drivers::parse_estimator(text.substr(0, slash));
  const auto p = drivers::parse_pwm(text.substr(slash + 1));
  if (!e || !p) return std::nullopt;
  return bench::Configuration{*e, *p};
}

// ?format=json|csv, or a 400 naming the field.
std::optional<std::string> format_of(const Request& req, Response& error) {
  const auto format = req.query.count("format") ? req.query.at("format") : std::string("json");
  if (format != "json" && format != "csv") {
    error = error_response(400, "bad_field", "format: '" + format + "' is not json or csv");
    return std::nullopt;
  }
  return format;
}

// ?offset=&limit= of the points route: a page of at most kMaxPointsPage points, the first page
// of that size when neither is given (so a sweep of up to that many points comes whole, as
// before paging existed).
constexpr std::size_t kMaxPointsPage = 10000;
struct Page {
  std::size_t offset = 0, limit = kMaxPointsPage;
};
std::optional<Page> page_of(const Request& req, Response& error) {
  Page page;
  const auto whole = [&](const char* name, std::size_t lo, std::size_t hi, std::size_t& out) {
    if (!req.query.count(name)) return true;
    const std::string& text = req.query.at(name);
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || text.front() == '-' || end != text.c_str() + text.size() || errno == ERANGE || v < lo || v > hi) {
      error = error_response(400, "bad_field", std::string(name) + ": '" + text + "' is not a whole number in [" +
                                                   std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return false;
    }
    out = static_cast<std::size_t>(v);
    return true;
  };
  if (!whole("offset", 0, std::numeric_limits<std::int64_t>::max(), page.offset)) return std::nullopt;
  if (!whole("limit", 1, kMaxPointsPage, page.limit)) return std::nullopt;
  return page;
}

Response db_error(const db::Error& e) {
  if (e.code == db::make_error_code(db::errc::not_found)) return error_response(404, "not_found", e.message);
  return error_response(500, "database", e.message);
}

// The calling thread's own connection to the store at `path`: the worker's reads never share
// the io thread's connection (a SQLite connection stays with one thread; WAL lets both read).
db::Store* thread_store(const std::filesystem::path& path, Response& error) {
  thread_local std::map<std::filesystem::path, db::Store> stores;
  if (const auto it = stores.find(path); it != stores.end()) return &it->second;
  auto opened = db::Store::open(path);
  if (!opened) {
    error = db_error(opened.error());
    return nullptr;
  }
  return &stores.emplace(path, std::move(*opened)).first->second;
}

// The sweep a route names and the calling thread's store: what each worker route on one sweep
// reads first (nullopt with `error` set when the id or the store fails).
struct SweepInStore {
  std::int64_t id;
  db::Store& store;
};
std::optional<SweepInStore> sweep_in_store(const Request& req, const std::filesystem::path& db_path, Response& error) {
  const auto id = sweep_id(req, error);
  if (!id) return std::nullopt;
  db::Store* own = thread_store(db_path, error);
  if (!own) return std::nullopt;
  return SweepInStore{*id, *own};
}

// The plan's points before speed restrictions: what its estimate costs.
std::size_t size_bound(const bench::SweepPlan& p) {
  const std::size_t pairs = p.operating_points.empty() ? p.speeds_rpm.size() * p.loads_Nm.size() : p.operating_points.size();
  return pairs * std::max<std::size_t>(1, p.angles_deg.size()) * std::max<std::size_t>(1, p.configurations.size());
}

// A plan's top level as the OpenAPI document publishes it and the router checks it;
// bench::parse_sweep_plan checks the rest (and unknown members: "_"-comments are allowed, which
// additionalProperties cannot say), each problem at its pointer.
synbench::Json plan_schema() {
  const synbench::Json object = {{"type", "object"}};
  return {{"type", "object"},
          {"description", "a sweep plan, docs/sweep-plan.md"},
          {"properties",
           {{"name", {{"type", "string"}}},
            {"preset", {{"oneOf", synbench::Json::array({{{"type", "string"}}, object})}, {"description", "a preset's name, or {\"name\": ..., options}"}}},
            {"dimensions", object},
            {"order", {{"type", "string"}, {"description", "e.g. speed-load-config-angle, outermost first"}}},
            {"mode", {{"type", "string"}, {"enum", synbench::Json::array({"grid", "adaptive"})}}},
            {"adaptive", object},
            {"gate", object},
            {"window_s", {{"type", "number"}, {"minimum", bench::kMinWindow_s}, {"maximum", 3600}}},
            {"precision", {{"type", "object"}, {"nullable", true},
                           {"description", "measure until sure: pdcm_u_repeat_target_W, max_window_s, mode"}}},
            {"thermal", object},
            {"limits", object},
            {"notes", {{"type", "array"}, {"items", {{"type", "string"}}}}}}}};
}

// A route whose body is a plan: a body the schema refuses is a `bad_plan`, as the parser's are.
Route plan_route(Route r) {
  r.body_error_code = "bad_plan";
  return r;
}

// POST /api/sweeps/{id}/abort's optional body: why, in the operator's words.
synbench::Json abort_schema() {
  return {{"type", "object"},
          {"additionalProperties", false},
          {"properties", {{"reason", {{"type", "string"}, {"maxLength", 500}, {"description", "why the sweep is aborted"}}}}}};
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// A viewer may estimate plans up to this size; an operator up to the plan parser's own limit.
constexpr std::size_t kViewerEstimatePoints = 100000;

}  // namespace

void add_sweep_routes(Router& router, db::Store& store, BenchRuntime& bench, ControlLock& control, Worker& worker,
                      std::filesystem::path db_path,
                      synbench::Json bench_config) {
  // The worker's connection is opened now, with the daemon's: opened on first use after the
  // file was deleted, it would make a new, empty database instead of noticing the loss.
  worker.post([db_path] {
    Response ignored;
    thread_store(db_path, ignored);
  });
  db::Store* db = &store;
  BenchRuntime* runtime = &bench;
  ControlLock* lock = &control;
  const bench::BenchSetpointLimits limits{bench.description().max_speed_rpm, bench.description().max_load_Nm};
  router.add({"POST", "/api/sweeps/{id}/start", Role::operator_,
              "Run the sweep on the daemon's bench (a stopped one resumes at its first missing point).",
              AsyncHandler([db, runtime, lock, db_path](const Request& req, Reply reply) {
                if (!lock->claim(req.caller_id)) return reply(locked(*lock));
                Response err;
                const auto id = sweep_id(req, err);
                if (!id) return reply(err);
                auto s = db->get_sweep(*id);
                if (!s) return reply(db_error(s.error()));
                if (s->state == db::SweepState::completed)
                  return reply(error_response(409, "invalid_state", "sweep " + std::to_string(*id) + " is already completed"));
                auto parsed = bench::parse_sweep_plan(s->meta.plan);
                if (!parsed.plan) return reply(error_response(500, "bad_plan", "the stored plan no longer parses"));
                auto rows = db->points(*id);
                if (!rows) return reply(db_error(rows.error()));
                std::map<std::size_t, bench::PointRecord> stored;
                for (const auto& row : *rows) stored[static_cast<std::size_t>(row.index)] = row.record;
                runtime->start_sweep(*id, std::move(*parsed.plan), std::move(stored), db_path, answer(std::move(reply), 202));
              })});
  for (const char* action : {"pause", "resume", "abort"}) {
    const std::string a = action;
    const std::string summary = a == "pause"    ? "Pause the running sweep after its point in flight."
                                : a == "resume" ? "Resume the paused sweep."
                                                : "Abort the running sweep: drop the point in flight, ordered stop. An "
                                                  "optional body {\"reason\": \"...\"} is stored as the sweep's last_error "
                                                  "and named in the events.";
    Route r{"POST", "/api/sweeps/{id}/" + a, Role::operator_, summary,
            AsyncHandler([runtime, lock, a](Request req, Reply reply) {
              if (!lock->claim(req.caller_id)) return reply(locked(*lock));
              Response err;
              const auto id = sweep_id(req, err);
              if (!id) return reply(err);
              std::string reason;
              // The body is optional (the CLI and older pages send none): checked here when given.
              if (a == "abort" && !req.body.empty()) {
                if (auto bad = check_body(abort_schema(), "bad_field", req)) return reply(std::move(*bad));
                if (req.json.contains("reason")) reason = trim(req.json["reason"].get<std::string>());
              }
              runtime->sweep_action(*id, a, answer(std::move(reply)), std::move(reason));
            })};
    if (a == "abort") {
      r.request_schema = abort_schema();
      r.body_checked_by_handler = true;
    }
    router.add(std::move(r));
  }
  router.add(plan_route({"POST", "/api/sweeps", Role::operator_,
              "Create a sweep from a plan (docs/sweep-plan.md): 201 with its id, state created.",
              [db, lock, bench_config, limits](const Request& req) {
                if (!lock->claim(req.caller_id)) return locked(*lock);
                auto plan = bench::parse_sweep_plan(req.json);
                if (!plan.errors.empty() || !plan.plan) return bad_plan(plan);
                if (auto bad = bad_for_bench(req.json, *plan.plan, limits)) return *bad;
                db::SweepMeta meta;
                meta.name = plan.plan->name.empty() ? "sweep" : plan.plan->name;
                meta.plan = bench::to_json(*plan.plan);
                meta.bench_config = bench_config;
                meta.total_points = static_cast<std::int64_t>(bench::estimate(*plan.plan).points);
                auto created = db->create_sweep(meta);
                if (!created) return db_error(created.error());
                auto s = db->get_sweep(*created);
                if (!s) return db_error(s.error());
                return json_response(201, sweep_json(*s, true));
              },
              plan_schema()}));
  router.add(answering({"GET", "/api/sweeps", Role::viewer, "Run history: every sweep in the store, by id.", [db](const Request&) {
                auto list = db->list_sweeps();
                if (!list) return db_error(list.error());
                synbench::Json out = synbench::Json::array();
                for (const auto& s : *list) out.push_back(sweep_json(s, false));
                return json_response(200, out);
              }},
              {{"type", "array"}, {"items", sweep_schema(false)}}));
  router.add(answering({"GET", "/api/sweeps/{id}", Role::viewer, "One sweep: state, progress, timestamps, its plan.",
              [db](const Request& req) {
                Response err;
                const auto id = sweep_id(req, err);
                if (!id) return err;
                auto s = db->get_sweep(*id);
                if (!s) return db_error(s.error());
                return json_response(200, sweep_json(*s, true));
              }},
              sweep_schema(true)));
  router.add(answering({"GET", "/api/sweeps/{id}/points", Role::viewer,
              "A sweep's stored points (docs/record.md): JSON, or CSV with ?format=csv; ?offset=&limit= pages them "
              "(at most 10000 a page; X-Total-Count gives the total).",
              worker.offload([db_path](const Request& req) {
                Response err;
                const auto sweep = sweep_in_store(req, db_path, err);
                if (!sweep) return err;
                const auto format = format_of(req, err);
                if (!format) return err;
                const auto page = page_of(req, err);
                if (!page) return err;
                if (auto s = sweep->store.get_sweep(sweep->id); !s) return db_error(s.error());
                auto rows = sweep->store.points(sweep->id);
                if (!rows) return db_error(rows.error());
                const std::span<const db::PointRow> all(*rows);
                const std::size_t first = std::min(page->offset, all.size());
                const auto slice = all.subspan(first, std::min(page->limit, all.size() - first));
                Response r;
                if (*format == "csv") {
                  r.content_type = "text/csv; charset=utf-8";
                  r.body = db::points_to_csv(slice);
                } else {
                  r.body = dump_json(db::points_to_json(slice));
                }
                r.headers.emplace_back("X-Total-Count", std::to_string(all.size()));
                return r;
              })},
              points_schema()));
  router.add(answering({"GET", "/api/sweeps/{id}/analysis", Role::viewer,
              "Analysis of a sweep's stored points (docs/analysis.md): JSON, or the curves as CSV with ?format=csv; "
              "?reference=ESTIMATOR/PWM (default encoder/capwm) for the deltas.",
              worker.offload([db_path](const Request& req) {
                Response err;
                const auto sweep = sweep_in_store(req, db_path, err);
                if (!sweep) return err;
                const auto format = format_of(req, err);
                if (!format) return err;
                bench::AnalysisOptions options;
                if (req.query.count("reference")) {
                  const auto ref = parse_configuration_label(req.query.at("reference"));
                  if (!ref)
                    return error_response(400, "bad_field", "reference: '" + req.query.at("reference") +
                                                                "' is not ESTIMATOR/PWM (e.g. encoder/capwm)");
                  options.reference = *ref;
                }
                const auto s = sweep->store.get_sweep(sweep->id);
                if (!s) return db_error(s.error());
                auto rows = sweep->store.points(sweep->id);
                if (!rows) return db_error(rows.error());
                std::vector<bench::PointRecord> records;
                records.reserve(rows->size());
                for (const auto& row : *rows) records.push_back(row.record);
                const auto analysis = bench::analyze(records, options);
                Response r;
                if (*format == "csv") {
                  r.content_type = "text/csv; charset=utf-8";
                  r.body = bench::analysis_curves_csv(analysis);
                } else {
                  auto j = bench::to_json(analysis);
                  // The adaptive searches and the precision target, replayed from the stored points.
                  if (const auto plan = bench::parse_sweep_plan(s->meta.plan).plan) {
                    std::map<std::size_t, bench::PointRecord> by_index;
                    for (const auto& row : *rows) by_index[static_cast<std::size_t>(row.index)] = row.record;
                    j["sweep_outcome"] = bench::to_json(bench::sweep_outcome(*plan, by_index));
                  }
                  r.body = dump_json(j);
                }
                return r;
              })},
              analysis_schema()));
  // The one-click report (docs/report.md): the same page and CSV as `synbench report`, built on the worker.
  const auto text_route = [](Route r, const char* type, const char* what) {
    r.response_content_type = type;
    return answering(std::move(r), {{"type", "string"}, {"description", what}});
  };
  router.add(text_route({"GET", "/api/sweeps/{id}/report", Role::viewer,
              "A sweep's report (docs/report.md): one self-contained HTML file (plan, metadata, every figure as inline "
              "SVG, tables, exclusions), as an attachment named synbench-report-ID-NAME-DATE.html.",
              worker.offload([db_path](const Request& req) {
                Response err;
                const auto sweep = sweep_in_store(req, db_path, err);
                if (!sweep) return err;
                auto report = report::make_sweep_report(sweep->store, sweep->id, report::current_context());
                if (!report) return db_error(report.error());
                Response r;
                r.content_type = "text/html; charset=utf-8";
                r.body = std::move(report->html);
                r.headers.emplace_back("Content-Disposition", "attachment; filename=\"" + report->base_name + ".html\"");
                return r;
              })},
              "text/html", "the report page"));
  router.add(text_route({"GET", "/api/sweeps/{id}/report.csv", Role::viewer,
              "Every stored point of a sweep as CSV (docs/record.md), unpaged, as an attachment named like the report "
              "(synbench-report-ID-NAME-DATE.csv).",
              worker.offload([db_path](const Request& req) {
                Response err;
                const auto sweep = sweep_in_store(req, db_path, err);
                if (!sweep) return err;
                auto s = sweep->store.get_sweep(sweep->id);
                if (!s) return db_error(s.error());
                auto rows = sweep->store.points(sweep->id);
                if (!rows) return db_error(rows.error());
                Response r;
                r.content_type = "text/csv; charset=utf-8";
                r.body = db::points_to_csv(*rows);
                r.headers.emplace_back("Content-Disposition", "attachment; filename=\"" +
                                       report::report_base_name(*s, report::current_context().generated_at) + ".csv\"");
                return r;
              })},
              "text/csv", "the points CSV"));
  router.add(answering({"GET", "/api/presets", Role::viewer, "The sweep presets (thesis grid, IEC 61800-9-2) as canonical plans.",
              [](const Request&) {
                synbench::Json out = synbench::Json::array();
                const auto add = [&out](std::string_view name, const char* description, const bench::SweepPlan& p) {
                  out.push_back({{"name", std::string(name)},
                                 {"description", description},
                                 {"plan", bench::to_json(p)},
                                 {"estimate", bench::to_json(bench::estimate(p))}});
                };
                add(bench::kThesisGridPreset,
                    "Thesis Sec. 6.3.2: 100..900 rpm step 200 x 0.5..3.5 N m step 0.5 x 40..76 deg step 2, the thesis's eight "
                    "configurations (HFI to 300 rpm, the EEMF variants from 500 rpm)",
                    bench::thesis_grid_plan());
                add(bench::kIecPreset, "IEC 61800-9-2 drive operating points (speed %, torque %) at 40..76 deg step 2",
                    bench::iec_61800_9_2_plan());
                return json_response(200, out);
              }},
              presets_schema()));
  router.add(worker.offloaded(answering(plan_route({"POST", "/api/sweeps/estimate", Role::viewer,
              "Validate a plan without creating a sweep: its canonical form, number of points and bench time.",
              [limits](const Request& req) {
                auto plan = bench::parse_sweep_plan(req.json);
                if (!plan.errors.empty() || !plan.plan) return bad_plan(plan);
                if (auto bad = bad_for_bench(req.json, *plan.plan, limits)) return *bad;
                if (req.caller != Role::operator_ && size_bound(*plan.plan) > kViewerEstimatePoints)
                  return error_response(413, "too_large", "a viewer may estimate plans of at most " +
                                                              std::to_string(kViewerEstimatePoints) + " points");
                const auto e = bench::estimate(*plan.plan);
                synbench::Json out = bench::to_json(e);
                out["duration_s"] = e.bench_time_s;
                out["plan"] = bench::to_json(*plan.plan);
                return json_response(200, out);
              },
              plan_schema()}),
                       estimate_schema(true))));
}

}  // namespace synbench::http
