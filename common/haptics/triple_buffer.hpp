#pragma once
// TripleBuffer<T>: lock-free hand-over of the newest value from one writer thread to one
// reader thread -- a front/back double buffer plus a spare slot, so that the writer never has
// to wait for the reader to let go of the front. The writer fills back() in place and
// publish()es it; the reader calls update() and reads front(). Each call is one atomic
// exchange; nothing allocates, nothing blocks. A value the reader never took is replaced by a
// newer one (the reader always sees the latest, never a torn one).
#include <array>
#include <atomic>

namespace sb::haptics {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // Writer side: the slot to fill (all of it: it holds an older value), then publish it.
  T& back() { return slots_[back_]; }
  void publish() { back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex; }

  // Reader side: takes the newest published value, if there is one; true when front() changed.
  bool update() {
    if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return true;
  }
  const T& front() const { return slots_[front_]; }
  // Reader side: whether update() would take a new value now (one relaxed load).
  bool pending() const { return (middle_.load(std::memory_order_relaxed) & kFresh) != 0; }

  // Before any thread starts: sets every slot (e.g. to reserve capacity).
  template <class F>
  void for_each_slot(F&& f) {
    for (T& s : slots_) f(s);
  }

 private:
  static constexpr unsigned kIndex = 3, kFresh = 4;
  std::array<T, 3> slots_{};
  unsigned back_ = 0;                // writer's slot
  unsigned front_ = 1;               // reader's slot
  std::atomic<unsigned> middle_{2};  // the hand-over slot, plus kFresh when not yet taken
};

}  // namespace sb::haptics
