// JSON Schemas of the routes' 200 answers, as /api/openapi.json publishes them. Each object lists
// every member the handler writes and no other (additionalProperties false), so a test that
// validates the handlers' live answers against these (tests/server/http) fails as soon as the
// code and the document part.
#pragma once

#include <initializer_list>
#include <string>

#include "drivers/json.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

// An object whose `properties` are all present except those named in `optional`, and no other
// member; null too when `nullable`.
synbench::Json closed_object(synbench::Json properties, bool nullable = false,
                             std::initializer_list<const char*> optional = {});

// `route` with `schema` as the schema of its 200 answer.
Route answering(Route route, synbench::Json schema);

synbench::Json status_schema();        // GET /api/bench/status, status_json()
synbench::Json health_schema();        // GET /api/health
synbench::Json bench_config_schema();  // GET /api/bench/config
synbench::Json lock_schema();          // GET/POST/DELETE /api/bench/lock, ControlLock::describe()
synbench::Json whoami_schema();        // GET /api/whoami
// A sweep as GET /api/sweeps lists it, or with its plan as GET /api/sweeps/{id} gives it.
synbench::Json sweep_schema(bool with_plan);
synbench::Json points_schema();        // GET /api/sweeps/{id}/points: point_index and the record (docs/record.md)
synbench::Json analysis_schema();      // GET /api/sweeps/{id}/analysis: the document's version tag
// A plan's estimate (bench::to_json(SweepEstimate)); POST /api/sweeps/estimate adds duration_s
// and the canonical plan.
synbench::Json estimate_schema(bool with_plan);
synbench::Json presets_schema();       // GET /api/presets
synbench::Json estimators_schema();    // GET /api/estimators: each source's own parameters beside the common members

}  // namespace synbench::http
