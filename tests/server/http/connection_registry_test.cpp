// The connection registry's choice of whom to close when the house is full: the least trusted,
// then the oldest; the client's own first when its share is the limit; never an operator.
#include "server/http/connection_registry.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace synbench::http {
namespace {

struct House {
  ConnectionRegistry reg;
  std::vector<std::string> closed;
  std::uint64_t add(const std::string& name, const std::string& client, Trust t = Trust::none) {
    const auto id = reg.add(client, [this, name] { closed.push_back(name); });
    reg.trust(id, t);
    return id;
  }
};

TEST(ConnectionRegistry, AFullHouseClosesTheOldestOfTheLeastTrusted) {
  House h;
  h.add("op", "10.0.0.1", Trust::operator_);
  h.add("viewer", "10.0.0.2", Trust::viewer);
  h.add("anon-old", "10.0.0.3");
  h.add("anon-new", "10.0.0.4");
  EXPECT_TRUE(h.reg.make_room("10.0.0.9", 4, 4));
  EXPECT_EQ(h.closed, std::vector<std::string>{"anon-old"});
  EXPECT_TRUE(h.reg.make_room("10.0.0.9", 2, 4));
  EXPECT_EQ(h.closed, (std::vector<std::string>{"anon-old", "anon-new", "viewer"}));
  EXPECT_EQ(h.reg.evicted(), 3u);
  // Only an operator is left: it is never closed, the newcomer is refused.
  EXPECT_FALSE(h.reg.make_room("10.0.0.9", 1, 4));
  EXPECT_EQ(h.closed.size(), 3u);
  EXPECT_EQ(h.reg.size(), 1u);
}

// Connections that never showed a token have a share of their own: at it, the oldest of them
// goes, even with room in the house; trusted connections are not counted and never go for it.
TEST(ConnectionRegistry, UntrustedConnectionsHaveAShareOfTheirOwn) {
  House h;
  h.add("viewer", "10.0.0.2", Trust::viewer);
  h.add("anon-old", "10.0.0.3");
  h.add("anon-new", "10.0.0.4");
  EXPECT_TRUE(h.reg.make_room("10.0.0.9", 100, 100, 3));
  EXPECT_TRUE(h.closed.empty()) << "2 untrusted, the newcomer the 3rd";
  EXPECT_TRUE(h.reg.make_room("10.0.0.9", 100, 100, 2));
  EXPECT_EQ(h.closed, std::vector<std::string>{"anon-old"});
  EXPECT_TRUE(h.reg.make_room("10.0.0.9", 100, 100, 1));
  EXPECT_EQ(h.closed, (std::vector<std::string>{"anon-old", "anon-new"}));
  EXPECT_EQ(h.reg.size(), 1u) << "the viewer stays";
}

TEST(ConnectionRegistry, AClientAtItsShareGivesUpItsOwnFirst) {
  House h;
  h.add("other-anon", "10.0.0.7");
  h.add("mine-viewer", "10.0.0.8", Trust::viewer);
  h.add("mine-anon", "10.0.0.8");
  EXPECT_TRUE(h.reg.make_room("10.0.0.8", 64, 2));
  EXPECT_EQ(h.closed, std::vector<std::string>{"mine-anon"}) << "not the other client's, though older";
  EXPECT_EQ(h.reg.count("10.0.0.8"), 1u);
}

TEST(ConnectionRegistry, TrustOnlyRisesAndAClosedOneIsForgotten) {
  House h;
  const auto a = h.add("a", "c", Trust::operator_);
  h.reg.trust(a, Trust::none);  // never lowered
  const auto b = h.add("b", "c");
  EXPECT_TRUE(h.reg.make_room("c", 2, 8));
  EXPECT_EQ(h.closed, std::vector<std::string>{"b"});
  h.reg.remove(b);  // the closed session's slot goes later: nothing happens
  EXPECT_EQ(h.reg.size(), 1u);
  h.reg.remove(a);
  EXPECT_EQ(h.reg.size(), 0u);
}

}  // namespace
}  // namespace synbench::http
