// What the store keeps besides the records themselves: sweeps with their metadata and state,
// stored points with their index, and events (faults, state changes, log lines).
#pragma once

#include "drivers/json.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/point_record.hpp"
#include "synbench/version.hpp"

namespace synbench::db {

// created -> running <-> paused -> completed | aborted | faulted; a faulted or aborted sweep may
// be resumed (-> running); completed is final. Stored as these names.
enum class SweepState { created, running, paused, completed, aborted, faulted };

std::string_view name(SweepState s) noexcept;
std::optional<SweepState> parse_sweep_state(std::string_view s) noexcept;

// One device of the bench as a sweep saw it: its role, its profile's name and the profile's
// version. Profiles carry no version number of their own, so the version is the profile's
// content digest ("fnv1a64:<16 hex digits>" of its canonical JSON, db/bench_identity.hpp): two
// sweeps with the same version ran the same register map. The in-process twin has no profile:
// profile "synbench twin", version synbench's own.
struct DeviceIdentity {
  std::string device;   // "synrm_drive", "load_drive", "vfc_meter"
  std::string profile;  // the profile's "name"
  std::string version;
  bool operator==(const DeviceIdentity&) const = default;
};

// Everything needed to know later how a sweep's points were obtained. JSON members that are
// null are stored as SQL NULL.
struct SweepMeta {
  std::string name;                           // for people; need not be unique
  synbench::Json plan;                // the sweep plan as run (expanded or as given)
  std::string software_version = kVersion;    // synbench's version
  synbench::Json profiles;            // the device profiles in use
  synbench::Json bench_config;        // the bench configuration in use
  synbench::Json calibration;         // meter/sensor calibration, if any
  std::int64_t total_points = 0;              // points in the plan: indices 0 .. total_points-1
  // The bench's identity (schema v9). Empty name or host: create_sweep stamps the store's
  // (StoreOptions::bench), whose defaults are this machine's host name for both.
  std::string bench_name;                     // --bench-name; defaults to the host name
  std::string bench_host;                     // the host the sweep was created on
  std::vector<DeviceIdentity> devices;        // empty: the store's
  // A deterministic name a study shard finds its sweep again by (find_sweep_by_key); unique
  // among the store's sweeps when set (create_sweep refuses a second one, errc::duplicate_key).
  std::optional<std::string> key;
};

// What a store's process writes as its bench: stamped on every sweep created without one.
struct BenchIdentity {
  std::string name;   // "" -> host
  std::string host;   // "" -> gethostname()
  std::vector<DeviceIdentity> devices;
};

struct Sweep {
  std::int64_t id = 0;
  SweepMeta meta;
  SweepState state = SweepState::created;
  std::string created_at;                   // UTC, ISO 8601 with milliseconds ("...T12:00:00.000Z")
  std::optional<std::string> started_at;    // first time the sweep ran
  std::optional<std::string> finished_at;   // when it last became completed, aborted or faulted
  std::optional<std::string> last_error;    // the last error given with a state change
  std::int64_t points_stored = 0;
};

// One stored point: its index in the sweep's plan and the record.
struct PointRow {
  std::int64_t index = 0;
  bench::PointRecord record;
};

// A sweep found `running` when a daemon starts (Store::abort_left_running): its process is gone
// (the sweep is marked aborted), or it may still run (left alone).
struct LeftRunning {
  std::int64_t sweep_id = 0;
  bool marked_aborted = false;
  std::string message;  // what was found and done, for the log
};

enum class EventKind { fault, state, log };

std::string_view name(EventKind k) noexcept;
std::optional<EventKind> parse_event_kind(std::string_view s) noexcept;

struct Event {
  std::int64_t id = 0;
  std::optional<std::int64_t> sweep_id;  // null for bench-wide events
  std::string at;                        // UTC, ISO 8601 with milliseconds
  EventKind kind = EventKind::log;
  std::string message;
};

}  // namespace synbench::db
