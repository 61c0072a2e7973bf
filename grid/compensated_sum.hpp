#pragma once
// Neumaier's compensated summation: the error of a long sum stays at one rounding of the
// result instead of growing with the number of terms. O(1) per term.
#include <cmath>

namespace sb::grid {

class CompensatedSum {
 public:
  void add(double v) {
    const double t = sum_ + v;
    if (std::abs(sum_) >= std::abs(v)) {
      compensation_ += (sum_ - t) + v;
    } else {
      compensation_ += (v - t) + sum_;
    }
    sum_ = t;
  }
  double value() const { return sum_ + compensation_; }

 private:
  double sum_ = 0.0;
  double compensation_ = 0.0;
};

}  // namespace sb::grid
