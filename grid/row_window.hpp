#pragma once
// RowWindow: the three rows iy - 1, iy, iy + 1 of a store whose heights are not contiguous
// (the sparse grid), held in a contiguous buffer for the dense erosion pass
// (erosion_kernel.hpp), which runs its vector classing and lane visits on them as on the
// dense grid. The window slides: the pass visits rows in order (iy + 1 or iy - 1 after iy),
// so of the three rows only the far one is new for the next row, and only the row left
// behind is final and written back.
//
// Use (one dense pass): load(iy, x0, x1) before the visits of row iy, extend(x0, x1) where
// they reach columns beyond, flush() after the last row. load() of a row next to the last
// one loaded slides the window; of any other row (a gap between the visited rows) it flushes
// and starts again.
//
// Design. A buffer of kRows rows of nx heights; the window is three consecutive rows of it
// from `base_` (node k = r * nx + ix of window row r, row iy - 1 + r: data() is the buffer
// at base_, so the middle row is at offset nx and the rows at stride nx, what the kernel's
// contiguous paths need). Sliding by a row moves base_ by one row in the pass's direction;
// when the window reaches the buffer's end, the two rows it keeps are copied to the other
// end first. Each held row has its own loaded columns [lo, hi]: load() and extend() grow a
// row's range to cover the columns asked for, reading only the columns it lacks. A second
// buffer holds each row as it was read (before_), so that write-back stores only the heights
// whose bits changed (SparseHeights::write_changed), as put() on the store would have.
//
// Exactness (the same heights as visiting on the store itself, bit for bit). The invariant,
// between visits: (a) every height in a held row's loaded columns is in the buffer and is
// the height the store would hold had every write gone to it; (b) every other height is
// right in the store. (b) holds for a held row's columns outside its range because nothing
// writes a column before it is loaded (the kernel reads and writes only rows iy - 1 .. iy + 1,
// columns it asked for with load / extend, and writes go to the buffer), and the row is
// written back only when it leaves the window. Reading a missing column from the store
// therefore keeps (a); a row left behind is written back (changed heights only) before
// anything else could read it from the store, which keeps (b) -- also if a later row brings
// it back into the window, when it is read afresh. flush() writes every held row back. So
// every visit reads exactly the heights it would read on the store, in the same order, and
// writes the same values: the same heights, the same rounding carry (the store's).
//
// Store: value_type, kRounds, read_row(iy, x0, x1, out), write_changed(iy, x0, x1, values,
// before) with before[] the heights the store holds there, carry() (SparseHeights).
//
// Memory: 2 x kRows x nx heights (2 x 16 x nx; double, nx = 161: 41 KiB), for the duration
// of a dense pass (allocated per pass, not counted in the terrain's bytes; not cleared:
// zeroing it cost about half of what the sliding saves). Costs: over a run of adjacent visited
// rows each row is read once and written back once, O(its columns): the union of the spans of
// the (at most three) visited rows whose window held it; every kRows - 2 slides the two kept
// rows are copied, O(their columns); load / extend O(the columns they add), flush O(columns
// held), z / put O(1). Sliding, a pass reads and writes each row once instead of three times;
// what the sparse grid still pays over the dense one is mostly these reads and write-backs
// (SparseHeights::read_row / write_changed, O(8) per block row). How to measure: callgrind's
// instructions of erode_ordered on the same scene with `--backend sparse` and `grid`, or
// tests/bench/sparse_bench.cpp.
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>

#include "grid/rounding_carry.hpp"

namespace sb::grid {

template <class Store>
class RowWindow {
 public:
  using Real = typename Store::value_type;
  static constexpr bool kRounds = Store::kRounds;
  static constexpr std::size_t kRows = 16;  // buffer rows: the window slides kRows - 3 rows between copies
  static_assert(kRows >= 4);

  RowWindow(Store& store, std::size_t nx, std::size_t ny)
      : store_(store),
        nx_(nx),
        ny_(ny),
        z_(std::make_unique_for_overwrite<Real[]>(kRows * nx)),
        before_(std::make_unique_for_overwrite<Real[]>(kRows * nx)) {}

  // Row iy with columns x0..x1 of the rows iy - 1 .. iy + 1 that exist: slides the window
  // when iy is next to the row loaded last, else writes everything back and starts again.
  void load(std::size_t iy, std::size_t x0, std::size_t x1) {
    if (held_ && iy == iy_ + 1)
      slide_up();
    else if (held_ && iy + 1 == iy_)
      slide_down();
    else
      start(iy);
    lo_ = x0, hi_ = x1;
    for (std::size_t r = 0; r < 3; ++r) cover(r, x0, x1);
  }
  // The loaded columns grown to hold x0..x1 (a span that grows at its end).
  void extend(std::size_t x0, std::size_t x1) {
    if (x0 >= lo_ && x1 <= hi_) return;
    lo_ = std::min(lo_, x0), hi_ = std::max(hi_, x1);
    for (std::size_t r = 0; r < 3; ++r) cover(r, lo_, hi_);
  }
  // The heights that changed, back into the store; the window is then empty.
  void flush() {
    if (!held_) return;
    for (std::size_t r = 0; r < 3; ++r) write_back(r);
    held_ = false;
  }

  double z(std::size_t k) const { return static_cast<double>(win_[k]); }
  double put(std::size_t k, double target) {
    win_[k] = static_cast<Real>(target);
    return rounding_error(target, win_[k]);
  }
  double& carry() { return store_.carry(); }
  Real* data() { return win_; }
  const Real* data() const { return win_; }

 private:
  struct Columns {
    std::size_t lo = 1, hi = 0;  // loaded columns of a window row (empty: lo > hi)
    bool empty() const { return lo > hi; }
  };

  // Window row r (row iy_ - 1 + r) lies in the grid.
  bool exists(std::size_t r) const { return iy_ + r >= 1 && iy_ + r - 1 < ny_; }
  Real* row(std::size_t r) { return win_ + r * nx_; }
  Real* row_before(std::size_t r) { return win_before_ + r * nx_; }
  void set_base(std::size_t base) {
    base_ = base;
    win_ = z_.get() + base * nx_;
    win_before_ = before_.get() + base * nx_;
  }

  void start(std::size_t iy) {
    flush();
    held_ = true;
    iy_ = iy;
    cols_[0] = cols_[1] = cols_[2] = Columns{};
    set_base(up_ ? 0 : kRows - 3);  // room to slide the way the last slide went
  }
  // From row iy_ to iy_ + 1: row iy_ - 1 is final; rows iy_, iy_ + 1 stay; row iy_ + 2 is new.
  void slide_up() {
    write_back(0);
    if (base_ + 4 > kRows) {  // no buffer row beyond the window: the kept rows to the start
      copy_rows(1, 0);
      set_base(0);
    } else {
      set_base(base_ + 1);
    }
    cols_[0] = cols_[1], cols_[1] = cols_[2], cols_[2] = Columns{};
    ++iy_;
    up_ = true;
  }
  // From row iy_ to iy_ - 1: row iy_ + 1 is final; rows iy_ - 1, iy_ stay; row iy_ - 2 is new.
  void slide_down() {
    write_back(2);
    if (base_ == 0) {  // no buffer row before the window: the kept rows to the end
      copy_rows(0, kRows - 2);
      set_base(kRows - 3);
    } else {
      set_base(base_ - 1);
    }
    cols_[2] = cols_[1], cols_[1] = cols_[0], cols_[0] = Columns{};
    --iy_;
    up_ = false;
  }
  // The two kept rows, window rows first and first + 1 (1, 2 going up; 0, 1 going down), to
  // buffer rows to, to + 1: their loaded columns, heights and heights as read.
  void copy_rows(std::size_t first, std::size_t to) {
    for (std::size_t i = 0; i < 2; ++i) {
      const Columns& c = cols_[first + i];
      if (c.empty()) continue;
      const std::size_t from = (base_ + first + i) * nx_ + c.lo, at = (to + i) * nx_ + c.lo;
      const std::size_t bytes = (c.hi - c.lo + 1) * sizeof(Real);
      std::memcpy(z_.get() + at, z_.get() + from, bytes);
      std::memcpy(before_.get() + at, before_.get() + from, bytes);
    }
  }
  // Window row r holds at least columns x0..x1 (a row outside the grid holds none).
  void cover(std::size_t r, std::size_t x0, std::size_t x1) {
    if (!exists(r)) return;
    Columns& c = cols_[r];
    if (c.empty()) {
      read(r, x0, x1);
      c = {x0, x1};
      return;
    }
    if (x0 < c.lo) read(r, x0, c.lo - 1), c.lo = x0;
    if (x1 > c.hi) read(r, c.hi + 1, x1), c.hi = x1;
  }
  void read(std::size_t r, std::size_t x0, std::size_t x1) {
    Real* z = row(r);
    store_.read_row(iy_ + r - 1, x0, x1, z + x0);
    std::memcpy(row_before(r) + x0, z + x0, (x1 - x0 + 1) * sizeof(Real));
  }
  void write_back(std::size_t r) {
    const Columns& c = cols_[r];
    if (c.empty()) return;
    store_.write_changed(iy_ + r - 1, c.lo, c.hi, row(r) + c.lo, row_before(r) + c.lo);
  }

  Store& store_;
  std::size_t nx_, ny_;
  // kRows rows of nx: the window's rows; as read from the store. Not initialised: only loaded
  // columns are ever read (by the window, and by the kernel, whose vector loads at a span's end
  // are masked).
  std::unique_ptr<Real[]> z_, before_;
  std::size_t base_ = 0;         // buffer row of window row 0
  Real* win_ = nullptr;          // z_ at base_ (data())
  Real* win_before_ = nullptr;   // before_ at base_
  bool held_ = false;            // rows are held (loaded since the last flush)
  bool up_ = true;               // the last slide went up
  std::size_t iy_ = 0;           // the row loaded last: window rows iy_ - 1 .. iy_ + 1
  std::size_t lo_ = 1, hi_ = 0;  // columns every held row of the window covers
  Columns cols_[3];              // loaded columns of each window row
};

}  // namespace sb::grid
