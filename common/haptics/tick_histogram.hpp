#pragma once
// TickHistogram: durations in microseconds binned at 0.25 us up to 5 ms (exact maximum kept),
// so the servo can record every tick for hours without allocating. Other non-negative values
// (the per-tick force change, in newtons) use their own bin width and range. add() is O(1);
// percentile() is O(bins). Single-threaded: the servo owns it, others read it after join.
#include <cstdint>
#include <vector>

namespace sb::haptics {

class TickHistogram {
 public:
  static constexpr double kBinUs = 0.25;
  static constexpr double kRangeUs = 5000.0;

  TickHistogram() : TickHistogram(kBinUs, kRangeUs) {}
  TickHistogram(double bin, double range) : bin_(bin), bins_(static_cast<std::size_t>(range / bin), 0) {}
  void add(double us) {
    if (!(us >= 0.0)) us = 0.0;
    ++count_;
    if (us > max_) max_ = us;
    const auto bin = static_cast<std::size_t>(us / bin_);
    if (bin < bins_.size())
      ++bins_[bin];
    else
      ++overflow_;
  }
  std::uint64_t count() const { return count_; }
  double max() const { return max_; }
  // q in [0, 1]: the upper edge of the bin holding the q-th duration (the exact maximum when
  // it lies beyond the range or q = 1). 0 when empty.
  double percentile(double q) const;

 private:
  double bin_;
  std::vector<std::uint32_t> bins_;
  std::uint64_t count_ = 0, overflow_ = 0;
  double max_ = 0.0;
};

}  // namespace sb::haptics
