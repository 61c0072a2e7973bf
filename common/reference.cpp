#include "common/reference.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace sb {

namespace {

// The pile the pile reference expects: the sand poured, plus a cone terrain's own sand (which
// stands on terrain.height_m around the domain's centre); the pour's centre otherwise.
struct PileSetup {
  double volume_m3 = 0.0;
  Vec2 centre{0.0, 0.0};
  bool on_cone = false;  // the base is terrain.height_m, not the initial surface
};

PileSetup pile_setup(const Scene& scene, const StampSchedule& schedule) {
  PileSetup p;
  for (const ToolStamp& s : schedule.stamps) p.volume_m3 += s.pour_volume_m3;
  p.centre = schedule.stamps.front().pose.xy;
  if (scene.terrain.kind == TerrainKind::Cone) {
    p.volume_m3 += scene.terrain.cone_volume_m3;
    p.centre = scene.domain.centre();
    p.on_cone = true;
  }
  return p;
}

// Least-squares slope of y against x; 0 with fewer than two distinct x.
double fitted_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const auto n = static_cast<double>(x.size());
  if (x.size() < 2) return 0.0;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  return sxx > 0 ? sxy / sxx : 0.0;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Distance from `centre` along `dir` at which the height first drops below `level`.
double ray_crossing(const Raster& h, const Vec2& centre, const Vec2& dir, double level, double max_r) {
  const double step = h.spacing_m / 4.0;
  double prev = h.interpolate(centre);
  for (double r = step; r <= max_r; r += step) {
    const double v = h.interpolate(centre + r * dir);
    if (v < level) return r - step * (level - v) / (prev - v);  // linear between samples
    prev = v;
  }
  return max_r;
}

Raster crater_reference(const ToolStamp& s, const HeightField& initial, const Raster& lattice) {
  // Cut volume and the rim rule's integral, by midpoint quadrature over the influence box.
  const Aabb2 box = s.influence_bounds();
  const int n = 1000;
  const Vec2 d = (box.hi - box.lo) / n;
  double cut = 0.0, rim = 0.0;
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const Vec2 p = box.lo + Vec2((ix + 0.5) * d.x(), (iy + 0.5) * d.y());
      if (s.contains(p))
        cut += std::max(0.0, initial(p) - s.bottom_z(p));
      else
        rim += s.rim_weight(p);
    }
  const double scale = rim > 0.0 ? cut / rim : 0.0;  // both in units of the quadrature cell
  Raster r = lattice;
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) {
      const Vec2 p = r.point(ix, iy);
      const double z0 = initial(p);
      r.at(ix, iy) = s.contains(p) ? std::min(z0, s.bottom_z(p)) : z0 + scale * s.rim_weight(p);
    }
  return r;
}

}  // namespace

std::optional<Raster> reference_raster(const Scene& scene, const StampSchedule& schedule, const HeightField& initial,
                                       const Raster& lattice) {
  if (schedule.stamps.empty()) return std::nullopt;
  const ToolStamp& first = schedule.stamps.front();
  switch (scene.reference) {
    case ReferenceKind::Pile: {
      const PileSetup pile = pile_setup(scene, schedule);
      const double t = scene.material.tan_critical();
      const double radius = cone_radius(pile.volume_m3, t);
      Raster r = lattice;
      for (std::size_t iy = 0; iy < r.ny; ++iy)
        for (std::size_t ix = 0; ix < r.nx; ++ix) {
          const Vec2 p = r.point(ix, iy);
          const double base = pile.on_cone ? scene.terrain.height_m : initial(p);
          r.at(ix, iy) = base + std::max(0.0, (radius - (p - pile.centre).norm()) * t);
        }
      return r;
    }
    case ReferenceKind::Crater:
      return crater_reference(first, initial, lattice);
    case ReferenceKind::Trench:
    case ReferenceKind::Ridge:
    case ReferenceKind::Plane:
    case ReferenceKind::None:
      return std::nullopt;
  }
  return std::nullopt;
}

PileShape measure_pile(const Raster& h, const Vec2& centre, double base_m) {
  PileShape shape;
  double peak = base_m;
  for (double v : h.values) peak = std::max(peak, v);
  shape.height_m = peak - base_m;
  if (!(shape.height_m > 0.0)) return shape;
  // Flank: height against radius where the pile is between 20% and 80% of its height.
  std::vector<double> radius, height;
  for (std::size_t iy = 0; iy < h.ny; ++iy)
    for (std::size_t ix = 0; ix < h.nx; ++ix) {
      const double above = h.at(ix, iy) - base_m;
      if (above > 0.2 * shape.height_m && above < 0.8 * shape.height_m) {
        radius.push_back((h.point(ix, iy) - centre).norm());
        height.push_back(above);
      }
    }
  shape.flank_angle_deg = rad_to_deg(std::atan(-fitted_slope(radius, height)));
  // Half-height contour and foot, along 180 rays.
  const double max_r = std::max(h.spacing_m * static_cast<double>(std::max(h.nx, h.ny)), 0.0);
  std::vector<double> half, foot;
  for (int k = 0; k < 180; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 180.0;
    const Vec2 dir(std::cos(a), std::sin(a));
    half.push_back(ray_crossing(h, centre, dir, base_m + 0.5 * shape.height_m, max_r));
    foot.push_back(ray_crossing(h, centre, dir, base_m + 0.01 * shape.height_m, max_r));
  }
  double mean = 0.0, var = 0.0;
  for (double r : half) mean += r;
  mean /= static_cast<double>(half.size());
  for (double r : half) var += (r - mean) * (r - mean);
  shape.roundness = mean > 0.0 ? std::sqrt(var / static_cast<double>(half.size())) / mean : 0.0;
  double foot_mean = 0.0;
  for (double r : foot) foot_mean += r;
  shape.radius_m = foot_mean / static_cast<double>(foot.size());
  // A ray that runs out of the raster before it finds the foot: the pile is cut by the border.
  shape.found = std::all_of(foot.begin(), foot.end(), [&](double r) { return r < max_r; }) &&
                std::isfinite(shape.flank_angle_deg) && std::isfinite(shape.roundness);
  return shape;
}

TrenchShape measure_trench(const Raster& h, const Raster& initial, const Vec2& a, const Vec2& b) {
  TrenchShape shape;
  const double length = (b - a).norm();
  if (length <= 0.0) return shape;
  const Vec2 along = (b - a) / length;
  const Vec2 across(-along.y(), along.x());
  std::vector<double> depths, angles;
  // Cross-sections over the middle half of the stroke, away from its ends.
  for (int k = 0; k <= 10; ++k) {
    const Vec2 c = a + (0.25 + 0.05 * k) * length * along;
    const double surface = initial.interpolate(c);
    const double bottom = h.interpolate(c);
    const double depth = surface - bottom;
    depths.push_back(depth);
    if (depth <= 0.0) continue;
    for (double side : {-1.0, 1.0}) {
      std::vector<double> x, y;
      const double step = h.spacing_m / 2.0;
      for (double d = 0.0; d < 0.5 * length; d += step) {
        const double z = h.interpolate(c + side * d * across);
        const double rise = z - bottom;
        if (rise > 0.2 * depth && rise < 0.8 * depth) {
          x.push_back(d);
          y.push_back(z);
        }
        if (rise >= 0.8 * depth) break;
      }
      if (x.size() >= 2) angles.push_back(rad_to_deg(std::atan(std::abs(fitted_slope(x, y)))));
    }
  }
  shape.depth_m = median(depths);
  shape.sections = static_cast<int>(angles.size());
  if (angles.empty()) return shape;
  double sum = 0.0, sq = 0.0;
  for (double v : angles) sum += v;
  shape.wall_angle_mean_deg = sum / static_cast<double>(angles.size());
  for (double v : angles) sq += (v - shape.wall_angle_mean_deg) * (v - shape.wall_angle_mean_deg);
  shape.wall_angle_spread_deg = std::sqrt(sq / static_cast<double>(angles.size()));
  shape.wall_angle_deg = *std::max_element(angles.begin(), angles.end());
  shape.wall_angle_min_deg = *std::min_element(angles.begin(), angles.end());
  return shape;
}

TrenchShape measure_ridge(const Raster& h, const Raster& initial, const Vec2& a, const Vec2& b) {
  Raster flipped = h, flipped_initial = initial;
  for (double& v : flipped.values) v = -v;
  for (double& v : flipped_initial.values) v = -v;
  return measure_trench(flipped, flipped_initial, a, b);
}

PlaneShape measure_plane(const Raster& h) {
  // Least squares z = c + gx (x - mx) + gy (y - my) over the raster points in the middle half
  // of each axis (centred coordinates decouple c from the slopes).
  std::vector<Vec2> p;
  std::vector<double> z;
  for (std::size_t iy = h.ny / 4; iy < h.ny - h.ny / 4; ++iy)
    for (std::size_t ix = h.nx / 4; ix < h.nx - h.nx / 4; ++ix) {
      p.push_back(h.point(ix, iy));
      z.push_back(h.at(ix, iy));
    }
  PlaneShape shape;
  if (p.size() < 3) return shape;
  const auto n = static_cast<double>(p.size());
  Vec2 m(0.0, 0.0);
  double mz = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) m += p[i], mz += z[i];
  m /= n;
  mz /= n;
  double sxx = 0, sxy = 0, syy = 0, sxz = 0, syz = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 d = p[i] - m;
    sxx += d.x() * d.x(), sxy += d.x() * d.y(), syy += d.y() * d.y();
    sxz += d.x() * (z[i] - mz), syz += d.y() * (z[i] - mz);
  }
  const double det = sxx * syy - sxy * sxy;
  if (!(det > 0.0)) return shape;
  shape.fitted = true;
  const double gx = (sxz * syy - syz * sxy) / det, gy = (syz * sxx - sxz * sxy) / det;
  shape.slope_deg = rad_to_deg(std::atan(std::hypot(gx, gy)));
  shape.azimuth_deg = rad_to_deg(std::atan2(-gy, -gx));
  double sq = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = z[i] - (mz + gx * (p[i].x() - m.x()) + gy * (p[i].y() - m.y()));
    sq += r * r;
  }
  shape.rms_m = std::sqrt(sq / n);
  // Local slopes over the same samples, where both neighbours along each axis exist.
  double local_sum = 0.0;
  std::size_t local_n = 0;
  const double two_h = 2.0 * h.spacing_m;
  for (std::size_t iy = std::max<std::size_t>(h.ny / 4, 1); iy + 1 < h.ny && iy < h.ny - h.ny / 4; ++iy)
    for (std::size_t ix = std::max<std::size_t>(h.nx / 4, 1); ix + 1 < h.nx && ix < h.nx - h.nx / 4; ++ix) {
      const double sx = (h.at(ix + 1, iy) - h.at(ix - 1, iy)) / two_h;
      const double sy = (h.at(ix, iy + 1) - h.at(ix, iy - 1)) / two_h;
      const double deg = rad_to_deg(std::atan(std::hypot(sx, sy)));
      local_sum += deg;
      shape.slope_max_deg = std::max(shape.slope_max_deg, deg);
      ++local_n;
    }
  shape.slope_mean_deg = local_n ? local_sum / static_cast<double>(local_n) : 0.0;
  return shape;
}

std::optional<std::string> reference_problem(const Scene& scene, const StampSchedule& schedule, const Raster& lattice) {
  if (schedule.stamps.empty()) return "the stroke has no stamps";
  const Aabb2 box{lattice.origin_m, lattice.point(lattice.nx - 1, lattice.ny - 1)};
  auto outside = [&](const Vec2& c, double r) {
    return c.x() - r < box.lo.x() || c.x() + r > box.hi.x() || c.y() - r < box.lo.y() || c.y() + r > box.hi.y();
  };
  auto text = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  const ToolStamp& first = schedule.stamps.front();
  switch (scene.reference) {
    case ReferenceKind::Pile: {
      const PileSetup pile = pile_setup(scene, schedule);
      const double radius = std::max(cone_radius(pile.volume_m3, scene.material.tan_critical()), scene.tool.radius_m);
      if (outside(pile.centre, radius))
        return "the pile's expected foot (a circle of radius " + text(radius) + " m around (" + text(pile.centre.x()) +
               ", " + text(pile.centre.y()) +
               "): the cone of the poured volume, or the pour's tool.radius_m) does not fit in the domain";
      return std::nullopt;
    }
    case ReferenceKind::Crater: {
      const Aabb2 reach = first.influence_bounds();
      if (reach.lo.x() < box.lo.x() || reach.hi.x() > box.hi.x() || reach.lo.y() < box.lo.y() ||
          reach.hi.y() > box.hi.y())
        return "the crater's footprint and rim band reach beyond the domain";
      return std::nullopt;
    }
    case ReferenceKind::Trench:
    case ReferenceKind::Ridge: {
      const auto& path = scene.stroke.path_m;
      const Vec2 a = path.front() + 0.25 * (path.back() - path.front());
      const Vec2 b = path.front() + 0.75 * (path.back() - path.front());
      if (outside(a, 0.0) || outside(b, 0.0))
        return "the middle half of the stroke, where it is measured, leaves the domain";
      return std::nullopt;
    }
    case ReferenceKind::Plane:
    case ReferenceKind::None:
      return std::nullopt;
  }
  return std::nullopt;
}

nlohmann::ordered_json accuracy_metrics(const Scene& scene, const StampSchedule& schedule, const HeightField& initial,
                                        const Raster& initial_raster, const Raster& final_raster,
                                        std::vector<std::string>* warnings) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  if (scene.reference == ReferenceKind::None || schedule.stamps.empty()) return j;
  j["reference"] = to_string(scene.reference);
  const std::string kind = to_string(scene.reference);
  auto absent = [&](const std::string& why) {
    if (warnings) warnings->push_back("the " + kind + " reference metrics are absent: " + why);
    return j;
  };
  if (const auto problem = reference_problem(scene, schedule, final_raster)) return absent(*problem);
  if (auto ref = reference_raster(scene, schedule, initial, final_raster)) {
    const RasterDifference d = compare_rasters(final_raster, *ref);
    j["reference.rmse_m"] = d.rmse_m;
    j["reference.max_error_m"] = d.max_abs_m;
  }
  const double crit = scene.material.critical_angle_deg;
  if (scene.reference == ReferenceKind::Pile) {
    const PileSetup pile = pile_setup(scene, schedule);
    const PileShape p =
        measure_pile(final_raster, pile.centre, pile.on_cone ? scene.terrain.height_m : initial(pile.centre));
    if (!p.found) {
      j.erase("reference.rmse_m");
      j.erase("reference.max_error_m");
      return absent("no pile was found whose foot lies within the domain around the pour point");
    }
    const double volume = pile.volume_m3;
    j["pile.flank_angle_deg"] = p.flank_angle_deg;
    j["pile.flank_angle_error_deg"] = p.flank_angle_deg - crit;
    j["pile.roundness"] = p.roundness;
    j["pile.radius_m"] = p.radius_m;
    j["pile.radius_expected_m"] = cone_radius(volume, scene.material.tan_critical());
    j["pile.height_m"] = p.height_m;
  }
  if (scene.reference == ReferenceKind::Trench || scene.reference == ReferenceKind::Ridge) {
    const auto& path = scene.stroke.path_m;
    const bool trench = scene.reference == ReferenceKind::Trench;
    const TrenchShape t = trench ? measure_trench(final_raster, initial_raster, path.front(), path.back())
                                 : measure_ridge(final_raster, initial_raster, path.front(), path.back());
    if (t.sections == 0)
      return absent(std::string("no cross-section has a ") + (trench ? "wall" : "flank") +
                    " to fit (the stroke left no " + (trench ? "trench" : "ridge") + " below 80% of its depth)");
    const std::string key = trench ? "trench.wall_" : "ridge.flank_";
    j[key + "angle_deg"] = t.wall_angle_deg;  // the steepest section
    j[key + "angle_mean_deg"] = t.wall_angle_mean_deg;
    j[key + "angle_min_deg"] = t.wall_angle_min_deg;
    j[key + "angle_spread_deg"] = t.wall_angle_spread_deg;
    j[key + "excess_deg"] = std::max(0.0, t.wall_angle_deg - crit);
    j[key + "mean_error_deg"] = t.wall_angle_mean_deg - crit;
    j[key + "worst_error_deg"] = t.worst_error_deg(crit);
    j[key + "sections"] = t.sections;
    j[trench ? "trench.depth_m" : "ridge.height_m"] = t.depth_m;
  }
  if (scene.reference == ReferenceKind::Plane) {
    const PlaneShape p = measure_plane(final_raster);
    if (!p.fitted) return absent("the middle half of the raster has too few samples for a plane");
    j["plane.slope_deg"] = p.slope_deg;
    j["plane.slope_error_deg"] = p.slope_deg - crit;
    j["plane.azimuth_deg"] = p.azimuth_deg;
    j["plane.rms_m"] = p.rms_m;
    j["plane.slope_mean_deg"] = p.slope_mean_deg;
    j["plane.slope_max_deg"] = p.slope_max_deg;
  }
  return j;
}

}  // namespace sb
