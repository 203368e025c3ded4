// See instance_id.hpp.
#include "server/http/instance_id.hpp"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <random>

namespace synbench::http {

const std::string& instance_id() {
  static const std::string id = [] {
    // The clock mixed in: two daemons started from one seed-poor random_device still differ.
    std::random_device rd;
    const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    std::mt19937_64 gen((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ now);
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(gen()));
    return std::string(buf);
  }();
  return id;
}

}  // namespace synbench::http
