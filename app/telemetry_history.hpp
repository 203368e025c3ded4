// The daemon's bounded memory of its telemetry: a ring of samples at most every `period_s` of
// bench time (20 Hz), `capacity` of them (18000: 15 min), oldest dropped first; about 64 bytes a
// sample, so the default holds ~1.2 MB whatever the uptime. Served as a trace to fill a page's
// charts on load, saved to a file (atomically: a temporary renamed over it) and loaded at start,
// so a restart keeps the trace: the loaded samples are moved to end before the new bench clock's
// present by the wall time the daemon was down (a visible gap). Thread-safe: the bench thread
// offers, the worker reads and saves, each under one short lock.
#pragma once

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <mutex>
#include <system_error>
#include <vector>

namespace synbench::app {

// One sample; NaN where the bench had no value (no drive telemetry, no temperature sensor).
struct TelemetrySample {
  static constexpr float kNone = std::numeric_limits<float>::quiet_NaN();
  double t_s = 0;  // bench time
  float speed_rpm = kNone, torque_Nm = kNone, im_A = kNone, id_A = kNone, iq_A = kNone, udc_V = kNone, pac_W = kNone,
        temp_C = kNone, pos_err_deg = kNone;
  float cmd_speed_rpm = kNone, cmd_load_Nm = kNone, cmd_angle_deg = kNone;  // what the bench commanded
  float enabled = 0;  // 1 while the drives ran
};

class TelemetryHistory {
 public:
  static constexpr std::size_t kDefaultCapacity = 18000;  // 15 min at 20 Hz
  static constexpr double kDefaultPeriod_s = 0.05;

  explicit TelemetryHistory(std::size_t capacity = kDefaultCapacity, double period_s = kDefaultPeriod_s);

  // Kept when at least period_s of bench time after the last kept sample (the input decimated to
  // the ring's rate), or when the bench clock went back.
  void offer(const TelemetrySample& s);
  // The samples of the last `span_s` of bench time (before the newest), oldest first; at most
  // `max_points` of them: every k-th, k as small as fits (the newest always included).
  std::vector<TelemetrySample> recent(double span_s, std::size_t max_points) const;
  std::size_t size() const;
  std::size_t capacity() const { return capacity_; }
  double period_s() const { return period_s_; }

  // Writes the ring to `file` through `file`.tmp and a rename; `wall_s`: the wall clock now
  // (seconds since the epoch), stored for the gap at load.
  std::error_code save(const std::filesystem::path& file, double wall_s) const;
  // Puts the samples of `file` before those held, shifted so that the last one lies
  // (wall_s - saved wall time, at least 1 s) before `now_s`. A missing file is no error;
  // a damaged one is refused (errc::invalid_argument) and nothing is loaded.
  std::error_code load(const std::filesystem::path& file, double now_s, double wall_s);

 private:
  std::vector<TelemetrySample> ordered() const;  // the lock held
  void push(const TelemetrySample& s);           // the lock held

  const std::size_t capacity_;
  const double period_s_;
  mutable std::mutex mutex_;
  std::vector<TelemetrySample> ring_;
  std::size_t head_ = 0;  // where the next sample goes once the ring is full
  double last_t_s_ = -std::numeric_limits<double>::infinity();
};

}  // namespace synbench::app
