// synbench's one JSON type. Keys keep the order they were written in, so what the daemon stores
// and serves (records, plans, configs) reads in the order the code and the user wrote it, and a
// document passes between layers without dump()/parse() round trips between two JSON types.
#pragma once

#include <nlohmann/json.hpp>

namespace synbench {

using Json = nlohmann::ordered_json;

}  // namespace synbench
