#include "grid/active_set.hpp"

#include <stdexcept>

namespace sb::grid {

ActiveSet::ActiveSet(std::size_t nodes, int idle_passes) : idle_passes_(idle_passes), state_(nodes, 0) {
  // The idle count shares 16 bits with the membership flag.
  if (idle_passes < 1 || idle_passes >= kMember)
    throw std::invalid_argument("ActiveSet: idle_passes must be in [1, 32767]");
}

std::span<const std::uint32_t> ActiveSet::begin_pass() {
  visiting_.swap(list_);
  list_.clear();
  for (std::uint32_t k : visiting_) state_[k] &= static_cast<std::uint16_t>(~kMember);
  return visiting_;
}

std::size_t ActiveSet::bytes() const {
  return state_.capacity() * sizeof(std::uint16_t) + (list_.capacity() + visiting_.capacity()) * sizeof(std::uint32_t);
}

void ActiveSet::check(std::vector<std::string>& problems) const {
  std::size_t flagged = 0;
  for (std::size_t k = 0; k < state_.size(); ++k) {
    if (state_[k] & kMember) {
      ++flagged;
    } else if (state_[k] != 0) {
      problems.push_back("active set: node " + std::to_string(k) + " is no member but has state " +
                         std::to_string(state_[k]));
    }
    if ((state_[k] & ~kMember) >= idle_passes_)
      problems.push_back("active set: node " + std::to_string(k) + " idle count " +
                         std::to_string(state_[k] & ~kMember) + " >= idle_passes");
  }
  std::vector<bool> seen(state_.size(), false);
  for (std::uint32_t k : list_) {
    if (k >= state_.size()) {
      problems.push_back("active set: index " + std::to_string(k) + " out of range");
      continue;
    }
    if (seen[k]) problems.push_back("active set: node " + std::to_string(k) + " listed twice");
    seen[k] = true;
    if (!(state_[k] & kMember)) problems.push_back("active set: node " + std::to_string(k) + " listed but not flagged");
  }
  if (flagged != list_.size())
    problems.push_back("active set: " + std::to_string(flagged) + " nodes flagged, " + std::to_string(list_.size()) +
                       " listed");
}

}  // namespace sb::grid
