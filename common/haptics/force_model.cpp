#include "common/haptics/force_model.hpp"

#include <algorithm>
#include <cmath>

namespace sb::haptics {

namespace {

double bottom_z(const ForceParams& p, const Vec3& tool, double dx, double dy) {
  if (p.profile == BottomProfile::Flat) return tool.z();
  const double R = p.sphere_radius_m;
  return tool.z() + R - std::sqrt(std::max(0.0, R * R - dx * dx - dy * dy));
}

}  // namespace

ForceOutput compute_force(const HeightPatch& patch, const Vec3& position_m, const Vec3& velocity_m_s,
                          double max_stiffness_n_per_m) {
  ForceOutput out;
  if (!patch.valid || patch.params.footprint_size < 3 || patch.heights.nx < 2) return out;
  const ForceParams& p = patch.params;
  const Raster& h = patch.heights;
  const Vec2 c = position_m.head<2>();
  out.surface_z_m = h.interpolate(c);

  // Footprint in lattice coordinates (u = (x - ox) / s).
  const double inv_s = 1.0 / h.spacing_m;
  const double ch = std::cos(p.heading_rad), sh = std::sin(p.heading_rad);
  std::array<Vec2, ForceParams::kMaxFootprint> poly;
  const int n = p.footprint_size;
  double vmin = 1e300, vmax = -1e300, umin = 1e300, umax = -1e300;
  for (int i = 0; i < n; ++i) {
    const Vec2& q = p.footprint[static_cast<std::size_t>(i)];
    const Vec2 w(c.x() + ch * q.x() - sh * q.y(), c.y() + sh * q.x() + ch * q.y());
    poly[static_cast<std::size_t>(i)] = (w - h.origin_m) * inv_s;
    umin = std::min(umin, poly[i].x());
    umax = std::max(umax, poly[i].x());
    vmin = std::min(vmin, poly[i].y());
    vmax = std::max(vmax, poly[i].y());
  }
  const double last_x = static_cast<double>(h.nx - 1), last_y = static_cast<double>(h.ny - 1);
  out.outside_patch = umin < 0.0 || vmin < 0.0 || umax > last_x || vmax > last_y;
  if (!(umax >= 0.0 && vmax >= 0.0 && umin <= last_x && vmin <= last_y)) return out;  // also catches NaN

  double depth_sum = 0.0;  // metres, summed over points
  int points = 0, contacts = 0;
  std::array<double, ForceParams::kMaxFootprint> xs;
  const int row_lo = std::max(0, static_cast<int>(std::ceil(vmin)));
  const int row_hi = std::min(static_cast<int>(h.ny) - 1, static_cast<int>(std::floor(vmax)));
  for (int iy = row_lo; iy <= row_hi; ++iy) {
    const double v = iy;
    int m = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
      const Vec2& a = poly[static_cast<std::size_t>(j)];
      const Vec2& b = poly[static_cast<std::size_t>(i)];
      if ((a.y() <= v) != (b.y() <= v))
        xs[static_cast<std::size_t>(m++)] = a.x() + (v - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    }
    std::sort(xs.begin(), xs.begin() + m);
    const double dy = h.origin_m.y() + v * h.spacing_m - c.y();
    for (int k = 0; k + 1 < m; k += 2) {
      const int lo = std::max(0, static_cast<int>(std::ceil(xs[static_cast<std::size_t>(k)])));
      const int hi =
          std::min(static_cast<int>(h.nx) - 1, static_cast<int>(std::floor(xs[static_cast<std::size_t>(k + 1)])));
      const double* row = h.values.data() + static_cast<std::size_t>(iy) * h.nx;
      for (int ix = lo; ix <= hi; ++ix) {
        const double dx = h.origin_m.x() + ix * h.spacing_m - c.x();
        const double depth = row[ix] - bottom_z(p, position_m, dx, dy);
        ++points;
        if (depth > 0.0) {
          depth_sum += depth;
          ++contacts;
        }
      }
    }
  }
  if (points == 0) {  // a footprint smaller than the lattice: feel the centre
    points = 1;
    const double depth = out.surface_z_m - position_m.z();
    if (depth > 0.0) {
      depth_sum = depth;
      contacts = 1;
    }
  }
  out.footprint_points = points;
  out.penetration_m = depth_sum / points;
  out.displaced_m3 = depth_sum * h.spacing_m * h.spacing_m;
  out.contact_fraction = static_cast<double>(contacts) / points;
  out.in_contact = contacts > 0;
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
