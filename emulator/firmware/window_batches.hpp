// Sums of one quantity over the B equal consecutive sub-windows (batches) of a measurement
// window, accumulated at the control rate: the bench takes the type A uncertainty of the
// window's mean from the scatter of the batch means, since the samples inside a window are
// correlated and their own standard deviation over sqrt(N) would fake precision.
#pragma once

#include <cstdint>
#include <vector>

namespace synbench::emulator::firmware {

// Batch k covers samples [k N/B, (k+1) N/B) of the window's N. The twin rounds a window to a
// multiple of B periods, so all batches are equal; a window shorter than B periods, or one the
// batches do not divide evenly, keeps none.
class WindowBatches {
 public:
  void reset(std::int64_t periods, int batches) {
    sums_.clear();
    next_ = 0;
    len_ = 0;
    if (batches < 2 || periods < batches || periods % batches != 0) return;
    len_ = periods / batches;
    sums_.assign(static_cast<std::size_t>(batches), 0.0);
  }
  // The batch the next sample falls in (-1 without batches).
  std::int64_t batch() const { return len_ ? next_ / len_ : -1; }
  // True when the next sample starts a batch.
  bool at_batch_start() const { return len_ && next_ % len_ == 0; }
  void add(double x) {
    if (!len_ || next_ >= len_ * static_cast<std::int64_t>(sums_.size())) return;
    sums_[static_cast<std::size_t>(next_ / len_)] += x;
    ++next_;
  }
  std::int64_t batch_length() const { return len_; }
  // The batch means scaled by `scale` (a unit conversion), in time order; empty without batches.
  std::vector<double> means(double scale = 1.0) const {
    std::vector<double> m;
    m.reserve(sums_.size());
    for (double s : sums_) m.push_back(scale * s / static_cast<double>(len_));
    return m;
  }

 private:
  std::vector<double> sums_;
  std::int64_t len_ = 0, next_ = 0;
};

}  // namespace synbench::emulator::firmware
