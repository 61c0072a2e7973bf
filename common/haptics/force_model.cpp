#include "common/haptics/force_model.hpp"

#include <algorithm>
#include <cmath>

#include "common/haptics/footprint_integral.hpp"

namespace sb::haptics {

namespace {

// The integrands of force_model.hpp over one cell of the patch, in lattice coordinates
// (u = (x - ox) / s): the cell's heights interpolated bilinearly, the tool bottom flat or a
// sphere cap around the tool's centre.
struct CellIntegrand {
  const ForceParams& params;
  double tool_z, centre_u, centre_v, spacing;
  double h00 = 0.0, h10 = 0.0, h01 = 0.0, h11 = 0.0;
  int i = 0, j = 0;

  double depth(const Vec2& q) const {
    const double a = q.x() - i, b = q.y() - j;
    const double h = (1.0 - b) * ((1.0 - a) * h00 + a * h10) + b * ((1.0 - a) * h01 + a * h11);
    if (params.profile != BottomProfile::SphereCap) return h - tool_z;
    const double du = q.x() - centre_u, dv = q.y() - centre_v;
    return h - bottom(du * du + dv * dv);
  }
  // The sphere cap's height at squared distance r2 (lattice units) from the tool's centre.
  double bottom(double r2) const {
    const double R = params.sphere_radius_m;
    return tool_z + R - std::sqrt(std::max(0.0, R * R - r2 * spacing * spacing));
  }
};

struct Sums {
  double displaced = 0.0;  // integral of max(0, depth), lattice area units times metres
  double contact = 0.0;    // integral of min(1, max(0, depth) / kContactDepth_m), lattice area units
};

// Both integrals over a piece of one cell: the piece fanned into triangles, each integrated by
// the edge-midpoint rule (exact for quadratics, so for the bilinear sand under a flat tool
// whatever the fan). Signed areas: a non-convex piece's fan still sums to its integral.
void integrate_piece(const CellIntegrand& g, const Vec2* piece, int n, Sums& sums) {
  auto add = [&](const Vec2& q, double w) {
    const double d = g.depth(q);
    if (d > 0.0) {
      sums.displaced += w * d;
      sums.contact += w * std::min(1.0, d / kContactDepth_m);
    }
  };
  for (int k = 1; k + 1 < n; ++k) {
    const Vec2 &p0 = piece[0], &p1 = piece[k], &p2 = piece[k + 1];
    const double area = 0.5 * ((p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y()));
    if (area == 0.0) continue;
    const double w = area / 3.0;
    add(0.5 * (p0 + p1), w);
    add(0.5 * (p1 + p2), w);
    add(0.5 * (p2 + p0), w);
  }
}

}  // namespace

ForceOutput compute_force(const HeightPatch& patch, const Vec3& position_m, const Vec3& velocity_m_s,
                          double max_stiffness_n_per_m) {
  ForceOutput out;
  if (!patch.valid || patch.params.footprint_size < 3 || patch.heights.nx < 2 || patch.heights.ny < 2) return out;
  const ForceParams& p = patch.params;
  const Raster& h = patch.heights;
  const Vec2 c = position_m.head<2>();
  out.surface_z_m = h.interpolate(c);

  // Footprint in lattice coordinates, and its area (tool coordinates: rotation keeps it).
  const double inv_s = 1.0 / h.spacing_m;
  const double ch = std::cos(p.heading_rad), sh = std::sin(p.heading_rad);
  std::array<Vec2, ForceParams::kMaxFootprint> poly;
  const int n = p.footprint_size;
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300, area2 = 0.0;
  for (int i = 0, k = n - 1; i < n; k = i++) {
    const Vec2& q = p.footprint[static_cast<std::size_t>(i)];
    const Vec2& r = p.footprint[static_cast<std::size_t>(k)];
    area2 += r.x() * q.y() - q.x() * r.y();
    const Vec2 w(c.x() + ch * q.x() - sh * q.y(), c.y() + sh * q.x() + ch * q.y());
    Vec2& l = poly[static_cast<std::size_t>(i)];
    l = (w - h.origin_m) * inv_s;
    umin = std::min(umin, l.x());
    umax = std::max(umax, l.x());
    vmin = std::min(vmin, l.y());
    vmax = std::max(vmax, l.y());
  }
  const double footprint_area = 0.5 * std::abs(area2);  // m^2
  const double last_x = static_cast<double>(h.nx - 1), last_y = static_cast<double>(h.ny - 1);
  out.outside_patch = umin < 0.0 || vmin < 0.0 || umax > last_x || vmax > last_y;
  if (!(umax >= 0.0 && vmax >= 0.0 && umin <= last_x && vmin <= last_y) || !(footprint_area > 0.0) ||
      !std::isfinite(position_m.z()))
    return out;                                                   // also catches NaN
  if (area2 < 0.0) std::reverse(poly.begin(), poly.begin() + n);  // counter-clockwise for signed areas

  CellIntegrand g{p, position_m.z(), (c.x() - h.origin_m.x()) * inv_s, (c.y() - h.origin_m.y()) * inv_s, h.spacing_m};
  Sums sums;
  const bool flat = p.profile == BottomProfile::Flat;
  // One cell's share of the integrals.
  auto cell = [&](const Vec2* piece, int count, int i, int j, bool whole) {
    const double* row = h.values.data() + static_cast<std::size_t>(j) * h.nx + i;
    g.h00 = row[0];
    g.h10 = row[1];
    g.h01 = row[h.nx];
    g.h11 = row[h.nx + 1];
    const double hmax = std::max(std::max(g.h00, g.h10), std::max(g.h01, g.h11));
    if (flat) {
      // Under a flat bottom the depth is bilinear, extreme at the corners: a cell whose corners
      // are all above the sand adds nothing; a whole cell whose corners are all deeper than
      // kContactDepth_m has bilinear integrands, and the midpoint rule's value (exact for them)
      // is the corners' mean, computed directly.
      if (hmax <= g.tool_z) return;
      const double lo = std::min(std::min(g.h00, g.h10), std::min(g.h01, g.h11)) - g.tool_z;
      if (whole && lo >= kContactDepth_m) {
        sums.displaced += 0.25 * (g.h00 + g.h10 + g.h01 + g.h11) - g.tool_z;
        sums.contact += 1.0;
        return;
      }
    } else {
      // A sphere cap is lowest at the cell's point nearest the tool's centre: a cell whose
      // sand stays above that adds nothing.
      const double du = std::max(0.0, std::max(i - g.centre_u, g.centre_u - (i + 1.0)));
      const double dv = std::max(0.0, std::max(j - g.centre_v, g.centre_v - (j + 1.0)));
      if (hmax <= g.bottom(du * du + dv * dv)) return;
    }
    g.i = i;
    g.j = j;
    integrate_piece(g, piece, count, sums);
  };
  thread_local FootprintCells<ForceParams::kMaxFootprint> cells;
  out.footprint_cells =
      cells.for_each_piece(poly.data(), n, static_cast<int>(h.nx) - 1, static_cast<int>(h.ny) - 1, cell);

  const double cell_area = h.spacing_m * h.spacing_m;
  out.displaced_m3 = std::max(0.0, sums.displaced * cell_area);
  out.penetration_m = out.displaced_m3 / footprint_area;
  out.contact_fraction = std::clamp(sums.contact * cell_area / footprint_area, 0.0, 1.0);
  out.in_contact = out.displaced_m3 > 0.0;
  if (!out.in_contact) return out;

  const double k = std::min(p.stiffness_n_per_m, max_stiffness_n_per_m);
  const double up = k * out.penetration_m;
  Vec3 f(0.0, 0.0, up);
  f -= p.drag_n_s_per_m * out.contact_fraction * velocity_m_s;
  const Vec2 vxy = velocity_m_s.head<2>();
  const double speed = vxy.norm();
  f.head<2>() -= p.friction * up * vxy / std::max(speed, kFrictionVelocityEps);
  out.force_n = f;
  return out;
}

LimitedForce limit_force(const Vec3& force_n, double max_force_n) {
  LimitedForce out;
  if (!force_n.allFinite() || !std::isfinite(max_force_n)) {
    out.nonfinite = true;
    return out;
  }
  const double limit = std::max(0.0, max_force_n);
  double norm = force_n.norm();
  if (!std::isfinite(norm)) norm = force_n.stableNorm();  // huge components overflow the plain norm
  if (norm > limit) {
    // A hair under the limit, so that rounding in the scaled norm cannot exceed it.
    out.force_n = force_n * (limit / norm * (1.0 - 1e-12));
    out.clamped = true;
  } else {
    out.force_n = force_n;
  }
  return out;
}

}  // namespace sb::haptics
