#pragma once
// DomainTiles: a domain cut into columns and rows of about equal sides, at most `max_side` along
// its longer side. Column k spans [x_edge(k), x_edge(k + 1)) (the last one closed at the
// domain's side), and col(x) names it exactly so, points outside falling into the border
// columns; rows alike. For change tracking and displays that tile a domain. O(1) each.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "common/geometry.hpp"

namespace sb {

class DomainTiles {
 public:
  DomainTiles(const Aabb2& domain, std::size_t max_side)
      : domain_(domain), cols_(count(domain, max_side, 0)), rows_(count(domain, max_side, 1)) {}

  std::size_t cols() const { return cols_; }
  std::size_t rows() const { return rows_; }
  std::size_t size() const { return cols_ * rows_; }
  double x_edge(std::size_t k) const { return edge(k, domain_.lo.x(), domain_.hi.x(), cols_); }
  double y_edge(std::size_t k) const { return edge(k, domain_.lo.y(), domain_.hi.y(), rows_); }
  std::size_t col(double x) const { return find(x, domain_.lo.x(), domain_.hi.x(), cols_); }
  std::size_t row(double y) const { return find(y, domain_.lo.y(), domain_.hi.y(), rows_); }

 private:
  static std::size_t count(const Aabb2& d, std::size_t max_side, int axis) {
    const double w = d.hi.x() - d.lo.x(), h = d.hi.y() - d.lo.y();
    const double longest = std::max(w, h), side = axis == 0 ? w : h;
    if (!(longest > 0.0)) return 1;
    return std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(max_side * side / longest)), 1, max_side);
  }
  static double edge(std::size_t k, double lo, double hi, std::size_t n) {
    if (k == 0) return lo;
    if (k >= n) return hi;
    return lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(n);
  }
  static std::size_t find(double x, double lo, double hi, std::size_t n) {
    if (!(x > lo)) return 0;  // (NaN too)
    if (!(x < hi)) return n - 1;
    std::size_t k = std::min(static_cast<std::size_t>((x - lo) / (hi - lo) * static_cast<double>(n)), n - 1);
    while (k > 0 && x < edge(k, lo, hi, n)) --k;  // the estimate's rounding, against the edges themselves
    while (k + 1 < n && x >= edge(k + 1, lo, hi, n)) ++k;
    return k;
  }

  Aabb2 domain_;
  std::size_t cols_, rows_;
};

}  // namespace sb
