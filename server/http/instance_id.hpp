// This daemon process's instance id: random, made once per start, sent in GET /api/health and
// the socket's hello so a page that outlives a daemon restart can tell the new daemon from the
// old one (and drop what it showed of the old one's events).
#pragma once

#include <string>

namespace synbench::http {

// 16 hex digits, the same for the whole life of the process.
const std::string& instance_id();

}  // namespace synbench::http
