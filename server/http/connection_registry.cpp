// The connection registry's bookkeeping; see connection_registry.hpp.
#include "server/http/connection_registry.hpp"

namespace synbench::http {

std::uint64_t ConnectionRegistry::add(std::string client, Closer close, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  const std::uint64_t id = next_id_++;
  entries_[id] = Entry{std::move(client), Trust::none, now, std::move(close)};
  return id;
}

void ConnectionRegistry::remove(std::uint64_t id) {
  std::lock_guard lock(mutex_);
  entries_.erase(id);
}

void ConnectionRegistry::trust(std::uint64_t id, Trust t) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(id);
  if (it != entries_.end() && static_cast<int>(t) > static_cast<int>(it->second.trust)) it->second.trust = t;
}

void ConnectionRegistry::set_closer(std::uint64_t id, Closer close) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(id);
  if (it != entries_.end()) it->second.close = std::move(close);
}

std::size_t ConnectionRegistry::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::size_t ConnectionRegistry::count(const std::string& client) const {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [id, e] : entries_) n += e.client == client;
  return n;
}

std::uint64_t ConnectionRegistry::evicted() const {
  std::lock_guard lock(mutex_);
  return evicted_;
}

std::map<std::uint64_t, ConnectionRegistry::Entry>::iterator ConnectionRegistry::victim(const std::string* client) {
  auto best = entries_.end();
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    const Entry& e = it->second;
    if (e.trust == Trust::operator_ || (client && e.client != *client)) continue;
    // In id order, so the first of the lowest trust is the oldest of it.
    if (best == entries_.end() || static_cast<int>(e.trust) < static_cast<int>(best->second.trust)) best = it;
  }
  return best;
}

void ConnectionRegistry::evict(std::map<std::uint64_t, Entry>::iterator it) {
  Closer close = std::move(it->second.close);
  entries_.erase(it);  // forgotten now: the slot's later remove() finds nothing
  ++evicted_;
  if (close) close();
}

bool ConnectionRegistry::make_room(const std::string& client, std::size_t max, std::size_t max_per_client,
                                   std::size_t max_untrusted) {
  std::lock_guard lock(mutex_);
  const auto untrusted = [&] {
    std::size_t n = 0;
    for (const auto& [id, e] : entries_) n += e.trust == Trust::none;
    return n;
  };
  // The lowest trust goes first: while any connection is untrusted, the victim is one of them.
  while (untrusted() >= max_untrusted) evict(victim(nullptr));
  const auto mine = [&] {
    std::size_t n = 0;
    for (const auto& [id, e] : entries_) n += e.client == client;
    return n;
  };
  while (mine() >= max_per_client) {
    const auto v = victim(&client);
    if (v == entries_.end()) return false;
    evict(v);
  }
  while (entries_.size() >= max) {
    const auto v = victim(nullptr);
    if (v == entries_.end()) return false;
    evict(v);
  }
  return true;
}

}  // namespace synbench::http
