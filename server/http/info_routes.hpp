// Read-only routes that describe the daemon to a client: who the caller is, the estimators the
// drive offers, the bench's devices and the device profiles (docs/api.md).
#pragma once

#include "emulator/twin_config.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/router.hpp"

namespace synbench::http {

// `twin`: the firmware's estimator settings the estimators route describes.
void add_info_routes(Router& router, const BenchRuntime& bench, const emulator::TwinConfig& twin);

}  // namespace synbench::http
