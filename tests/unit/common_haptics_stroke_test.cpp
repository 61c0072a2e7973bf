// The shipped recorded stroke (experiments/haptics_stroke.csv on flat_stroke.toml) replayed
// through the servo tick on every back-end, with the simulation's part done in step every
// 5 ticks, deterministically: stamp when the tool is in the sand and has moved a stroke spacing
// (or gone half a spacing deeper), erode, simplify, republish the patch -- the rule of the
// interactive simulation (harness/interactive/sim.cpp), without its threads. The rendered
// force must stay continuous (per-tick change within the scene's force-rate limit), finite,
// within the device's limit and passive, and still push back as hard as the raw model does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/erosion.hpp"
#include "common/haptics/onset_lag.hpp"
#include "common/haptics/replay_device.hpp"
#include "common/haptics/servo_core.hpp"
#include "common/metrics.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/runner.hpp"
#include "terrain_test_support.hpp"

namespace sb::haptics {
namespace {

constexpr double kDt = 0.001;
constexpr int kSimEvery = 5;  // ticks per simulation step

struct StrokeRun {
  std::vector<double> steps_n, steady_n;   // per-tick change; |F| in steady contact
  std::vector<double> error_n;             // |force sent - the model's force at the same pose|
  double onset_lag_s = 0.0, held_n = 0.0;  // onset_lag.hpp: the largest lag, the last held force
  std::uint64_t onsets = 0;
  double force_max_n = 0.0, energy_j = 0.0;
  bool finite = true;
  std::uint64_t stamps = 0;
};

StrokeRun replay_stroke(const PreparedScene& prepared, const Trajectory& stroke, const std::string& backend,
                        const RenderingOptions& rendering) {
  const Scene& scene = prepared.scene;
  std::unique_ptr<Terrain> terrain = make_terrain(backend, scene, prepared.initial);
  DeviceLimits lim;  // the interactive defaults
  lim.max_force_n = 8.0;
  lim.max_stiffness_n_per_m = 2000.0;
  lim.workspace.lo = Vec3(scene.domain.box().lo.x(), scene.domain.box().lo.y(), -1.0);
  lim.workspace.hi = Vec3(scene.domain.box().hi.x(), scene.domain.box().hi.y(), 1.0);
  ReplayDevice device(stroke, lim);
  PatchBuffer patches;
  const ForceParams base = ForceParams::from(scene.material, scene.tool);
  const PatchLayout layout = PatchLayout::for_tool(base.reach_m, std::max(0.015, 0.5 * base.reach_m));
  reserve_patches(patches, layout.cells);
  std::uint64_t version = 0;
  Vec2 patch_centre = stroke.samples.front().position_m.head<2>();
  ForceParams params = base;
  auto republish = [&](const Vec2& centre) {
    fill_patch(*terrain, centre, layout, params, ++version, patches.back());
    patches.publish();
    patch_centre = centre;
  };
  republish(patch_centre);
  const ErosionRule rule = sb::test::rule_of(scene);
  ServoCore core(device, patches, 40.0, rendering, kDt);
  core.start();

  StrokeRun r;
  OnsetLag onset(kDt);
  bool have_stamp = false;
  Vec2 last_xy(0, 0);
  double last_z = 0.0;
  Vec3 last_force = Vec3::Zero();
  const double bottom = std::min_element(stroke.samples.begin(), stroke.samples.end(), [](auto& a, auto& b) {
                          return a.position_m.z() < b.position_m.z();
                        })->position_m.z();
  const int ticks = static_cast<int>(stroke.duration_s() / kDt) + 100;
  for (int i = 0; i < ticks; ++i) {
    const ServoState s = core.step(i * kDt);
    r.finite &= s.force_n.allFinite();
    r.force_max_n = std::max(r.force_max_n, s.force_n.norm());
    r.steps_n.push_back((s.force_n - last_force).norm());
    last_force = s.force_n;
    const Vec3 model = limit_force(s.model_force_n, lim.max_force_n).force_n;
    r.error_n.push_back((s.force_n - model).norm());
    onset.add(model.norm(), s.force_n.norm());
    const Vec3 p = s.device.position_m;
    if (p.z() <= bottom + 1e-4 && s.velocity_m_s.head<2>().norm() > 0.01) r.steady_n.push_back(s.force_n.norm());
    if (i % kSimEvery != kSimEvery - 1) continue;

    const Vec2 xy = p.head<2>();
    const double moved = have_stamp ? (xy - last_xy).norm() : 0.0;
    bool changed = false;
    if (s.model.in_contact && s.model.penetration_m >= 1e-4 &&
        (!have_stamp || moved >= scene.stroke.spacing_m || last_z - p.z() >= 0.5 * scene.stroke.spacing_m)) {
      const Vec2 dir = have_stamp && moved > 1e-9 ? Vec2((xy - last_xy) / moved) : Vec2::Zero();
      ToolPose pose;
      pose.xy = xy;
      pose.bottom_z = p.z();
      pose.heading_rad = dir.squaredNorm() > 0.0 ? std::atan2(dir.y(), dir.x()) : params.heading_rad;
      terrain->stamp(make_stamp(scene.tool, pose, dir, static_cast<std::uint32_t>(r.stamps++)));
      params.heading_rad = pose.heading_rad;
      have_stamp = true;
      last_xy = xy;
      last_z = p.z();
      changed = true;
    }
    changed |= terrain->erode(rule, ErosionBudget{scene.erosion.max_passes_per_step, 20000}).transfers > 0;
    if (changed) terrain->simplify(SimplifyParams{scene.tin.alpha_flat_deg});
    if (changed || (xy - patch_centre).norm() > (layout.half_m - params.reach_m) / 3.0) republish(xy);
  }
  r.energy_j = core.passivity().energy_j();
  onset.finish();
  r.onset_lag_s = onset.lag_max_s();
  r.onsets = onset.onsets();
  r.held_n = onset.held_force_n();
  return r;
}

// A smooth motion as experiments/haptics_trajectory.py writes it: 0.2 s above the sand, a
// minimum-jerk plunge from 3 mm above to 10 mm into it, a hold of 0.4 s, a minimum-jerk stroke
// of 0.1 m at `heading`, a hold, the lift, 0.2 s above. Sampled every millisecond.
Trajectory smooth_motion(double heading_rad, double stroke_s, double plunge_s) {
  auto blend = [](double s) {
    s = std::clamp(s, 0.0, 1.0);
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
  };
  const Vec2 centre(0.35355339, 0.35355339), dir(std::cos(heading_rad), std::sin(heading_rad));
  const Vec2 start = centre - 0.05 * dir;
  const double top = 0.103, bottom = 0.09, hold = 0.4;
  const double t_plunge = 0.2, t_stroke = t_plunge + plunge_s + hold, t_lift = t_stroke + stroke_s + hold;
  const double end = t_lift + plunge_s + 0.2;
  Trajectory t;
  for (int i = 0; i * 0.001 <= end; ++i) {
    const double at = i * 0.001;
    const double down = blend((at - t_plunge) / plunge_s) - blend((at - t_lift) / plunge_s);
    const Vec2 xy = start + 0.1 * blend((at - t_stroke) / stroke_s) * dir;
    t.samples.push_back({at, Vec3(xy.x(), xy.y(), top + (bottom - top) * down), 0});
  }
  return t;
}

TEST(HapticsStroke, SmoothMotionsAreRenderedAsTheModelComputesThemOnEveryBackend) {
  // Plunges peaking at 0.2 m/s (13 mm in 0.122 s) and slower, strokes at three headings and
  // speeds, a disk, a box and a sphere-capped disk: with the shipped settings the force sent
  // is the continuous model's (the rate limit, a fault guard, never acts; the blend covers the
  // patch swaps), with no lag at contact onset, and continuous from tick to tick.
  PreparedScene prepared = prepare_scene(load_scene(SB_SOURCE_DIR "/experiments/scenes/flat_stroke.toml"));
  const ToolSpec disk = prepared.scene.tool;
  ToolSpec box = disk, sphere = disk;
  box.shape = ToolShape::Box;
  box.half_size_m = Vec2(0.02, 0.01);
  sphere.profile = BottomProfile::SphereCap;
  sphere.sphere_radius_m = 0.05;
  struct Motion {
    const char* name;
    ToolSpec tool;
    double heading_rad, stroke_s, plunge_s;
  };
  const Motion motions[] = {{"disk 45deg 1.5 s", disk, 0.785398, 1.5, 0.122},
                            {"box 0deg 0.8 s", box, 0.0, 0.8, 0.122},
                            {"sphere 120deg 2.5 s", sphere, 2.0944, 2.5, 0.3}};
  RenderingOptions unlimited = prepared.scene.haptics;
  unlimited.max_force_rate_n_per_s = 0.0;
  for (const std::string& backend : backend_names()) {
    for (const Motion& m : motions) {
      SCOPED_TRACE(backend + ", " + m.name);
      prepared.scene.tool = m.tool;
      const Trajectory motion = smooth_motion(m.heading_rad, m.stroke_s, m.plunge_s);
      for (const RenderingOptions& rendering : {prepared.scene.haptics, unlimited}) {
        const StrokeRun r = replay_stroke(prepared, motion, backend, rendering);
        const double step_max = *std::max_element(r.steps_n.begin(), r.steps_n.end());
        const double step_p999 = percentile(r.steps_n, 0.999);
        const double error_p99 = percentile(r.error_n, 0.99);
        std::printf(
            "%s, %s, rate limit %g N/s: step max %.3f N, p99.9 %.3f N; sent - model p99 %.3f N, max %.3f N; "
            "%llu onsets, lag %.1f ms, held %.2f N\n",
            backend.c_str(), m.name, rendering.max_force_rate_n_per_s, step_max, step_p999, error_p99,
            *std::max_element(r.error_n.begin(), r.error_n.end()), static_cast<unsigned long long>(r.onsets),
            1e3 * r.onset_lag_s, r.held_n);
        EXPECT_TRUE(r.finite);
        EXPECT_LE(step_max, 0.3);
        EXPECT_LE(error_p99, 0.2);
        EXPECT_EQ(r.onsets, 1u);
        EXPECT_LE(r.onset_lag_s, 0.003);
        EXPECT_LE(r.energy_j, 1e-9);
      }
    }
  }
}

TEST(HapticsStroke, ReplayedStrokeIsContinuousPassiveAndStillPushesBackOnEveryBackend) {
  const PreparedScene prepared = prepare_scene(load_scene(SB_SOURCE_DIR "/experiments/scenes/flat_stroke.toml"));
  const Trajectory stroke = load_trajectory(SB_SOURCE_DIR "/experiments/haptics_stroke.csv");
  const RenderingOptions rendering = prepared.scene.haptics;  // the documented defaults
  RenderingOptions raw;                                       // the force model's output as it is, patch after patch
  raw.blend_s = 0.0;
  raw.max_force_rate_n_per_s = 0.0;
  raw.passivity = false;
  const double limit_n = rendering.max_force_rate_n_per_s * kDt;
  for (const std::string& backend : backend_names()) {
    SCOPED_TRACE(backend);
    const StrokeRun r = replay_stroke(prepared, stroke, backend, rendering);
    const StrokeRun before = replay_stroke(prepared, stroke, backend, raw);
    EXPECT_GT(r.stamps, 15u);
    EXPECT_TRUE(r.finite);
    EXPECT_LE(r.force_max_n, 8.0);
    EXPECT_LE(*std::max_element(r.steps_n.begin(), r.steps_n.end()), limit_n + 1e-12);
    EXPECT_LE(r.energy_j, 1e-9);
    // Without the rendering the stamps are felt as steps of newtons (this is what it fixes).
    const double raw_max = *std::max_element(before.steps_n.begin(), before.steps_n.end());
    EXPECT_GT(raw_max, 0.5);
    // The sand still pushes back: steady contact force within 15% of the raw model's. (The
    // rendering blends each patch in over blend_ms, so the tool meets the bulldozed pile ahead
    // of it on a patch up to that old, before the next stamp has cut it: the rendered force sits
    // above the raw model's by more under tool.displacement = "bulldoze" than under "rim".)
    ASSERT_GT(r.steady_n.size(), 1000u);
    const double steady = percentile(r.steady_n, 0.5), steady_raw = percentile(before.steady_n, 0.5);
    EXPECT_GT(steady, 2.0);
    EXPECT_NEAR(steady, steady_raw, 0.15 * steady_raw);
    std::printf(
        "%s: per-tick change p99.9 %.3f N (raw %.3f), max %.3f N (raw %.3f); steady |F| %.2f N (raw %.2f); "
        "observer %.3g J\n",
        backend.c_str(), percentile(r.steps_n, 0.999), percentile(before.steps_n, 0.999),
        *std::max_element(r.steps_n.begin(), r.steps_n.end()), raw_max, steady, steady_raw, r.energy_j);
  }
}

}  // namespace
}  // namespace sb::haptics
