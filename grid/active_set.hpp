#pragma once
// ActiveSet: the nodes erosion visits (the paper's list L_e), in a deterministic order.
//
// A list of node indices plus one 16-bit state per node (a membership bit and the count of
// consecutive idle visits). A pass takes the list out (begin_pass) and refills it: a node
// that transferred, and its neighbours, come back with a fresh idle count; an idle node
// comes back until it has been idle `idle_passes` times in a row. Order = order of
// insertion, so the same input gives the same sequence of visits.
//
// Memory: 2 bytes per node, plus 4 bytes per entry of the two index lists (their
// high-water mark). activate / idle / keep are O(1); begin_pass is O(list).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sb::grid {

class ActiveSet {
 public:
  ActiveSet(std::size_t nodes, int idle_passes);

  // Node k changed (or a neighbour of it did): in the set, idle count reset.
  void activate(std::uint32_t k) {
    if (!(state_[k] & kMember)) list_.push_back(k);
    state_[k] = kMember;
  }
  // Node k was visited and stayed put: one more idle visit; it leaves at idle_passes,
  // unless a neighbour brought it back during this pass.
  void idle(std::uint32_t k) {
    if (state_[k] & kMember) return;
    const std::uint16_t count = static_cast<std::uint16_t>(state_[k] + 1);
    if (count < idle_passes_) {
      state_[k] = count | kMember;
      list_.push_back(k);
    } else {
      state_[k] = 0;  // left the set; a non-member's state is always 0
    }
  }
  // Node k was not visited (the budget ran out): it stays as it was.
  void keep(std::uint32_t k) {
    if (state_[k] & kMember) return;
    state_[k] |= kMember;
    list_.push_back(k);
  }

  // Hands out the current members for one pass and empties the set; the pass refills it
  // through activate / idle / keep. The span stays valid until the next begin_pass.
  std::span<const std::uint32_t> begin_pass();

  bool empty() const { return list_.empty(); }
  std::size_t size() const { return list_.size(); }
  std::span<const std::uint32_t> members() const { return list_; }
  bool contains(std::uint32_t k) const { return state_[k] & kMember; }
  std::size_t bytes() const;
  // Bookkeeping invariants: every listed node flagged once, every flag listed, idle
  // counts below idle_passes, non-members zero. O(nodes).
  void check(std::vector<std::string>& problems) const;

 private:
  static constexpr std::uint16_t kMember = 0x8000;
  int idle_passes_;
  std::vector<std::uint16_t> state_;     // kMember | idle count, per node
  std::vector<std::uint32_t> list_;      // members, in visiting order
  std::vector<std::uint32_t> visiting_;  // the pass in progress
};

}  // namespace sb::grid
