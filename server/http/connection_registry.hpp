// Who holds the daemon's connections, so that a full house makes room for an operator. Every
// HTTP and WebSocket connection is registered with its client's address and how far it has
// shown itself trusted (none, a viewer's token, an operator's). When a new connection would
// exceed the limit (all clients, or one client's share), the oldest connection of the lowest
// trust below an operator's is closed to make room: connections that trickle bytes or never
// authenticate cannot keep an operator from the E-stop, and an operator's connection is never
// the one closed. Used from the io thread; a mutex keeps it safe from any other.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace synbench::http {

enum class Trust { none = 0, viewer = 1, operator_ = 2 };

class ConnectionRegistry {
 public:
  using Clock = std::chrono::steady_clock;
  // Closes a connection: called at most once, on the thread that makes room; it must only post
  // the close to the connection's own strand.
  using Closer = std::function<void()>;

  std::uint64_t add(std::string client, Closer close, Clock::time_point now = Clock::now());
  void remove(std::uint64_t id);
  // Raises a connection's trust (never lowers it).
  void trust(std::uint64_t id, Trust t);
  // The connection's closer from now on (a connection upgraded to a WebSocket changes owner).
  void set_closer(std::uint64_t id, Closer close);

  std::size_t size() const;
  std::size_t count(const std::string& client) const;
  std::uint64_t evicted() const;

  // Makes room for one more connection from `client` within `max` in all, `max_per_client` for
  // it and `max_untrusted` of connections that never showed a valid token (the newcomer is one):
  // closes (and forgets) as many of the oldest, least trusted connections below an operator's
  // as needed, the client's own first when its share is the limit. False when only operators
  // hold what would have to go: the new connection must be refused.
  bool make_room(const std::string& client, std::size_t max, std::size_t max_per_client,
                 std::size_t max_untrusted = SIZE_MAX);

 private:
  struct Entry {
    std::string client;
    Trust trust = Trust::none;
    Clock::time_point since;
    Closer close;
  };
  // The victim among `entries` (of `client` only when given): lowest trust, then oldest.
  std::map<std::uint64_t, Entry>::iterator victim(const std::string* client);
  void evict(std::map<std::uint64_t, Entry>::iterator it);

  mutable std::mutex mutex_;
  std::map<std::uint64_t, Entry> entries_;  // by id: ids grow, so the first is the oldest
  std::uint64_t next_id_ = 1;
  std::uint64_t evicted_ = 0;
};

// One registered connection for as long as it lives (an HTTP session, then the WebSocket
// session it became): removed from the registry when the last owner lets go.
class ConnectionSlot {
 public:
  ConnectionSlot(std::shared_ptr<ConnectionRegistry> registry, std::uint64_t id) : registry_(std::move(registry)), id_(id) {}
  ~ConnectionSlot() { registry_->remove(id_); }
  ConnectionSlot(const ConnectionSlot&) = delete;
  ConnectionSlot& operator=(const ConnectionSlot&) = delete;
  void trust(Trust t) { registry_->trust(id_, t); }
  void set_closer(ConnectionRegistry::Closer close) { registry_->set_closer(id_, std::move(close)); }

 private:
  std::shared_ptr<ConnectionRegistry> registry_;
  std::uint64_t id_;
};

}  // namespace synbench::http
