#pragma once
// SpscRing<T>: a fixed-capacity single-producer single-consumer queue. push() never blocks
// or allocates (it fails when full, and the caller counts the loss); pop() drains. Used to
// carry servo samples out of the 1 kHz thread. Each operation is O(1), two atomics.
#include <atomic>
#include <cstddef>
#include <vector>

namespace sb::haptics {

template <class T>
class SpscRing {
 public:
  // capacity is rounded up to a power of two.
  explicit SpscRing(std::size_t capacity) {
    std::size_t c = 1;
    while (c < capacity) c <<= 1;
    slots_.resize(c);
    mask_ = c - 1;
  }

  bool push(const T& v) {  // producer only
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) > mask_) return false;
    slots_[head & mask_] = v;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  bool pop(T& out) {  // consumer only
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  std::size_t capacity() const { return mask_ + 1; }

 private:
  std::vector<T> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
};

}  // namespace sb::haptics
