// The telemetry ring and its file; see telemetry_history.hpp.
#include "app/telemetry_history.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>

namespace synbench::app {

namespace {

// The file: this magic, the wall time of the save, the sample count, then the samples as they
// are in memory (the same build reads them: a format version in the magic guards a change).
constexpr char kMagic[8] = {'S', 'B', 'T', 'H', 'I', 'S', '0', '1'};

}  // namespace

TelemetryHistory::TelemetryHistory(std::size_t capacity, double period_s)
    : capacity_(std::max<std::size_t>(1, capacity)), period_s_(period_s) {
  ring_.reserve(capacity_);
}

void TelemetryHistory::push(const TelemetrySample& s) {
  if (ring_.size() < capacity_) {
    ring_.push_back(s);
  } else {
    ring_[head_] = s;
    head_ = (head_ + 1) % capacity_;
  }
  last_t_s_ = s.t_s;
}

void TelemetryHistory::offer(const TelemetrySample& s) {
  std::lock_guard lock(mutex_);
  // A small tolerance: a tick a little early still counts, so 100 Hz offers keep every 5th.
  if (s.t_s >= last_t_s_ && s.t_s < last_t_s_ + period_s_ * 0.999) return;
  push(s);
}

std::vector<TelemetrySample> TelemetryHistory::ordered() const {
  std::vector<TelemetrySample> out;
  out.reserve(ring_.size());
  out.insert(out.end(), ring_.begin() + static_cast<std::ptrdiff_t>(head_), ring_.end());
  out.insert(out.end(), ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(head_));
  return out;
}

std::size_t TelemetryHistory::size() const {
  std::lock_guard lock(mutex_);
  return ring_.size();
}

std::vector<TelemetrySample> TelemetryHistory::recent(double span_s, std::size_t max_points) const {
  std::vector<TelemetrySample> all;
  {
    std::lock_guard lock(mutex_);
    all = ordered();
  }
  if (all.empty() || max_points == 0) return {};
  const double from = all.back().t_s - span_s;
  const auto first = std::lower_bound(all.begin(), all.end(), from,
                                      [](const TelemetrySample& s, double t) { return s.t_s < t; });
  const auto n = static_cast<std::size_t>(all.end() - first);
  if (n == 0) return {};
  const std::size_t k = (n + max_points - 1) / max_points;
  std::vector<TelemetrySample> out;
  out.reserve(std::min(n, max_points));
  // Counted back from the newest, so the latest sample is always in.
  for (std::size_t back = (n - 1) % k; back < n; back += k) out.push_back(*(first + static_cast<std::ptrdiff_t>(back)));
  return out;
}

std::error_code TelemetryHistory::save(const std::filesystem::path& file, double wall_s) const {
  std::vector<TelemetrySample> all;
  {
    std::lock_guard lock(mutex_);
    all = ordered();
  }
  const auto tmp = std::filesystem::path(file.string() + ".tmp");
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return std::make_error_code(std::errc::io_error);
    const std::uint64_t n = all.size();
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&wall_s), sizeof wall_s);
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(reinterpret_cast<const char*>(all.data()), static_cast<std::streamsize>(n * sizeof(TelemetrySample)));
    out.flush();
    if (!out) return std::make_error_code(std::errc::io_error);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  return ec;
}

std::error_code TelemetryHistory::load(const std::filesystem::path& file, double now_s, double wall_s) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};  // nothing saved yet
  char magic[sizeof kMagic] = {};
  double saved_wall_s = 0;
  std::uint64_t n = 0;
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(&saved_wall_s), sizeof saved_wall_s);
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!in || std::memcmp(magic, kMagic, sizeof kMagic) != 0 || n > capacity_ * 16)
    return std::make_error_code(std::errc::invalid_argument);
  std::vector<TelemetrySample> loaded(n);
  in.read(reinterpret_cast<char*>(loaded.data()), static_cast<std::streamsize>(n * sizeof(TelemetrySample)));
  if (!in || !std::is_sorted(loaded.begin(), loaded.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; }))
    return std::make_error_code(std::errc::invalid_argument);
  if (loaded.empty()) return {};
  std::lock_guard lock(mutex_);
  auto held = ordered();
  // The loaded trace ends the daemon's down time (at least 1 s) before the oldest sample held.
  const double end_s = (held.empty() ? now_s : std::min(now_s, held.front().t_s)) - std::max(1.0, wall_s - saved_wall_s);
  const double shift = end_s - loaded.back().t_s;
  ring_.clear();
  head_ = 0;
  last_t_s_ = -std::numeric_limits<double>::infinity();
  const std::size_t skip = loaded.size() + held.size() > capacity_ ? std::min(loaded.size(), loaded.size() + held.size() - capacity_) : 0;
  for (std::size_t i = skip; i < loaded.size(); ++i) {
    TelemetrySample s = loaded[i];
    s.t_s += shift;
    push(s);
  }
  for (const auto& s : held) push(s);
  return {};
}

}  // namespace synbench::app
