// Read-only routes that describe the daemon to a client: who the caller is, the estimators the
// drive offers, the bench's devices and the device profiles (docs/api.md).
#pragma once

#include "server/http/bench_runtime.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

void add_info_routes(Router& router, BenchRuntime& bench);

}  // namespace synbench::http
