#pragma once
// StampSchedule: a stroke (polyline, optional bottom z per waypoint, spacing) turned into the
// sequence of ToolStamps every back-end receives. The sequence is lazy: stamp i is built when
// asked for (O(tool sides + log waypoints)), so a schedule's memory does not grow with its
// stamp count or the tool's side count.
#include <cstddef>
#include <functional>
#include <iterator>
#include <vector>

#include "common/tool.hpp"

namespace sb {

struct Stroke {
  std::vector<Vec2> path_m;  // waypoints, at least one
  std::vector<double> z_m;   // tool bottom z per waypoint; empty: surface - depth
  double spacing_m = 0.005;  // arc length between stamps
  int repeat = 1;            // trace the whole stroke this many times
};

// A read-only random-access sequence of stamps generated on demand. Copies share the
// generator. Elements are returned by value.
class StampSequence {
 public:
  using Generator = std::function<ToolStamp(std::size_t index)>;
  StampSequence() = default;
  StampSequence(std::size_t count, Generator generator) : count_(count), generate_(std::move(generator)) {}

  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  ToolStamp operator[](std::size_t i) const { return generate_(i); }
  ToolStamp front() const { return generate_(0); }
  ToolStamp back() const { return generate_(count_ - 1); }

  class iterator {
   public:
    using iterator_category = std::input_iterator_tag;
    using value_type = ToolStamp;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = ToolStamp;
    iterator(const StampSequence* seq, std::size_t i) : seq_(seq), i_(i) {}
    ToolStamp operator*() const { return (*seq_)[i_]; }
    iterator& operator++() {
      ++i_;
      return *this;
    }
    bool operator==(const iterator& o) const { return i_ == o.i_; }
    bool operator!=(const iterator& o) const { return i_ != o.i_; }

   private:
    const StampSequence* seq_;
    std::size_t i_;
  };
  iterator begin() const { return {this, 0}; }
  iterator end() const { return {this, count_}; }

 private:
  std::size_t count_ = 0;
  Generator generate_;
};

struct StampSchedule {
  StampSequence stamps;
  double length_m = 0.0;  // arc length of one trace
};

// Arc-length positions 0, s, 2s, ... along the polyline, plus its end when the last gap is
// not a whole spacing (so first and last waypoints are always stamped). A one-point path
// gives one position. stamp_arc_count and stamp_arc_position give the same positions one by
// one in O(1); stamp_arc_positions lists them (O(count)).
std::size_t stamp_arc_count(double length_m, double spacing_m);
double stamp_arc_position(double length_m, double spacing_m, std::size_t count, std::size_t k);
std::vector<double> stamp_arc_positions(double length_m, double spacing_m);
double polyline_length(const std::vector<Vec2>& path);

// `initial_height` gives the surface before the stroke; used for the bottom z when the
// stroke has no z per waypoint (bottom = surface - tool depth). The schedule keeps a copy of
// the function and calls it as stamps are generated: whatever it references must outlive
// the schedule (capture by value when in doubt).
StampSchedule make_schedule(const ToolSpec& tool, const Stroke& stroke,
                            const std::function<double(const Vec2&)>& initial_height);

}  // namespace sb
