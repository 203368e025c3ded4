// The declaration of synbench's one JSON type (drivers/json.hpp), for headers that only name it.
#pragma once

#include <nlohmann/json_fwd.hpp>

namespace synbench {

using Json = nlohmann::ordered_json;

}  // namespace synbench
