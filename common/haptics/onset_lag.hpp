#pragma once
// OnsetLag: how much later than the force model the force sent reaches a contact's force.
// A contact onset is a tick where the model's force becomes non-zero after at least
// kQuietS without force. Over the onset's window (kWindowS, cut short when the model's force
// returns to zero), the held force is the mean of the model's force magnitude over the
// window's last kHeldS; the lag is the time the force sent first reaches 90 % of it minus
// the time the model's force first did (the window's end when the sent force never does). A
// rendering that adds no delay has lag 0; a rate limit of r N/s adds about 0.9 F / r.
// Memory for one window is reserved up front: add() never allocates and costs O(1), except
// on the tick that closes a window (O(window)).
#include <algorithm>
#include <cstdint>
#include <vector>

namespace sb::haptics {

class OnsetLag {
 public:
  static constexpr double kWindowS = 0.3, kHeldS = 0.1, kQuietS = 0.05, kLevel = 0.9;

  explicit OnsetLag(double period_s = 0.001) : period_s_(period_s) {
    const auto n = static_cast<std::size_t>(kWindowS / period_s + 0.5);
    model_.reserve(n);
    sent_.reserve(n);
  }

  // One tick: the magnitudes of the model's force and of the force sent.
  void add(double model_n, double sent_n) {
    if (!tracking_) {
      if (model_n > 0.0 && quiet_ticks_ * period_s_ >= kQuietS) {
        tracking_ = true;
        model_.clear();
        sent_.clear();
      } else {
        quiet_ticks_ = model_n > 0.0 ? 0 : quiet_ticks_ + 1;
        return;
      }
    }
    if (model_n <= 0.0 || model_.size() == model_.capacity()) {
      close();
      quiet_ticks_ = model_n > 0.0 ? 0 : 1;
      return;
    }
    model_.push_back(model_n);
    sent_.push_back(sent_n);
  }
  // Closes an open window (at the end of a run).
  void finish() {
    if (tracking_) close();
  }

  std::uint64_t onsets() const { return onsets_; }
  double lag_max_s() const { return onsets_ ? lag_max_s_ : 0.0; }
  double held_force_n() const { return held_n_; }  // the last onset's held force

 private:
  void close() {
    tracking_ = false;
    const std::size_t n = model_.size();
    const auto held_ticks = static_cast<std::size_t>(kHeldS / period_s_ + 0.5);
    if (n < 2 * held_ticks) return;  // a touch too short to hold a force: not an onset
    double held = 0.0;
    for (std::size_t i = n - held_ticks; i < n; ++i) held += model_[i];
    held /= static_cast<double>(held_ticks);
    const double level = kLevel * held;
    auto first = [&](const std::vector<double>& f) {
      return static_cast<std::size_t>(std::find_if(f.begin(), f.end(), [&](double x) { return x >= level; }) -
                                      f.begin());
    };
    const double lag = (static_cast<double>(first(sent_)) - static_cast<double>(first(model_))) * period_s_;
    lag_max_s_ = onsets_ ? std::max(lag_max_s_, lag) : lag;
    held_n_ = held;
    ++onsets_;
  }

  double period_s_;
  bool tracking_ = false;
  std::uint64_t quiet_ticks_ = 0;
  std::vector<double> model_, sent_;
  std::uint64_t onsets_ = 0;
  double lag_max_s_ = 0.0, held_n_ = 0.0;
};

}  // namespace sb::haptics
