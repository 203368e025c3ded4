// Failed sign-ins (an unknown bearer token over HTTP or in a WebSocket's auth message) on
// stderr, for the operator's journal: the first at once, then at most one line every 10 s with
// how many were held back, so a guessing client cannot flood the log.
#pragma once

#include <chrono>
#include <string>

namespace synbench::http {

// `client` is the peer's address, `where` what it tried ("GET /api/bench/status", "/ws auth").
void log_failed_sign_in(const std::string& client, const std::string& where,
                        std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

}  // namespace synbench::http
