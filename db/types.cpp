// Names of sweep states and event kinds as stored in the database.
#include "db/types.hpp"

#include <array>

namespace synbench::db {
namespace {

constexpr std::array<std::string_view, 6> kStateNames{"created",   "running", "paused",
                                                      "completed", "aborted", "faulted"};
constexpr std::array<std::string_view, 3> kEventKindNames{"fault", "state", "log"};

}  // namespace

std::string_view name(SweepState s) noexcept { return kStateNames[static_cast<std::size_t>(s)]; }

std::optional<SweepState> parse_sweep_state(std::string_view s) noexcept {
  for (std::size_t i = 0; i < kStateNames.size(); ++i)
    if (kStateNames[i] == s) return static_cast<SweepState>(i);
  return std::nullopt;
}

std::string_view name(EventKind k) noexcept { return kEventKindNames[static_cast<std::size_t>(k)]; }

std::optional<EventKind> parse_event_kind(std::string_view s) noexcept {
  for (std::size_t i = 0; i < kEventKindNames.size(); ++i)
    if (kEventKindNames[i] == s) return static_cast<EventKind>(i);
  return std::nullopt;
}

}  // namespace synbench::db
