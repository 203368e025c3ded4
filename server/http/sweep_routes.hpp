// Sweep routes over the daemon's SQLite store (DATA_DIR/synbench.db): create a sweep from a
// plan, run it on the daemon's bench (start, pause, resume, abort), the run history,
// and each sweep's points as JSON or CSV. The Store is one connection used only from the HTTP
// thread, as db/store.hpp asks.
#pragma once

#include "drivers/json.hpp"

#include "db/store.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/router.hpp"
#include "server/http/worker.hpp"

namespace synbench::http {

// `bench_config`: the twin config in use, stored with each created sweep. `db_path`: the
// store's file, which the bench thread opens for the sweep it runs.
// The estimate, a sweep's points and its analysis run on `worker` (their own store connection
// there), off the io thread.
void add_sweep_routes(Router& router, db::Store& store, BenchRuntime& bench, ControlLock& control, Worker& worker,
                      std::filesystem::path db_path,
                      synbench::Json bench_config);

}  // namespace synbench::http
