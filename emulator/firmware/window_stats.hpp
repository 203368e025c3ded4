// Mean, min and max of one quantity accumulated at the control rate over a measurement window.
#pragma once

#include <algorithm>
#include <limits>

namespace synbench::emulator::firmware {

class WindowStats {
 public:
  void reset() { *this = WindowStats{}; }
  void add(double x) {
    sum_ += x;
    min_ = std::min(min_, x);
    max_ = std::max(max_, x);
    ++n_;
  }
  double mean() const { return n_ ? sum_ / static_cast<double>(n_) : 0.0; }
  double min() const { return min_; }
  double max() const { return max_; }
  long count() const { return n_; }

 private:
  double sum_ = 0;
  double min_ = std::numeric_limits<double>::infinity();
  double max_ = -std::numeric_limits<double>::infinity();
  long n_ = 0;
};

}  // namespace synbench::emulator::firmware
