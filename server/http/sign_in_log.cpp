// The rate-limited log of failed sign-ins; see sign_in_log.hpp.
#include "server/http/sign_in_log.hpp"

#include <cstdint>
#include <iostream>
#include <mutex>

namespace synbench::http {

void log_failed_sign_in(const std::string& client, const std::string& where, std::chrono::steady_clock::time_point now) {
  static std::mutex mutex;
  static std::chrono::steady_clock::time_point last{};
  static bool logged = false;
  static std::uint64_t held_back = 0;
  std::lock_guard lock(mutex);
  if (logged && now - last < std::chrono::seconds(10)) {
    ++held_back;
    return;
  }
  std::cerr << "synbench serve: failed sign-in from " << client << " (" << where << ": unknown token)";
  if (held_back) std::cerr << "; " << held_back << " more in the last " << std::chrono::duration_cast<std::chrono::seconds>(now - last).count() << " s";
  std::cerr << "\n";
  logged = true;
  last = now;
  held_back = 0;
}

}  // namespace synbench::http
