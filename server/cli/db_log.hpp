// The log line of a storage failure (a lost database file, a full disk, SQLite's own errors) on
// stderr, for the daemon and `synbench sweep`: the store's message names the file and carries
// SQLite's text and extended code. A failure repeated by every request (the dashboard polls the
// sweep list) is logged once until another one comes.
#pragma once

#include <functional>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>

#include "db/error.hpp"

namespace synbench::cli {

inline std::function<void(const db::Error&)> db_error_logger(std::string prefix) {
  struct Last {
    std::mutex mutex;
    std::string message;
  };
  // Stores on several threads (the daemon's io and bench threads) may share one logger.
  auto last = std::make_shared<Last>();
  return [prefix = std::move(prefix), last](const db::Error& e) {
    std::lock_guard lock(last->mutex);
    if (e.message == last->message) return;
    last->message = e.message;
    std::cerr << prefix << "database error: " << e.message << std::endl;
  };
}

}  // namespace synbench::cli
