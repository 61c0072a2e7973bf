#include "common/haptics/tick_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace sb::haptics {

double TickHistogram::percentile(double q) const {
  if (count_ == 0) return 0.0;
  if (q >= 1.0) return max_;
  const auto rank = static_cast<std::uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(max_, (static_cast<double>(b) + 1.0) * bin_);
  }
  return max_;
}

}  // namespace sb::haptics
