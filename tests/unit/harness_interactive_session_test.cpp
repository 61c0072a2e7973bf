// Sessions: the record/replay file, the simulation thread driven by a replay device without
// a window, and a recorded session replayed by `sandbench run --replay` on both back-ends.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <thread>

#include "common/haptics/replay_device.hpp"
#include "common/input_error.hpp"
#include "harness/interactive/device.hpp"
#include "harness/interactive/sim.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/backends.hpp"
#include "harness_test_support.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

using test::sandbench;  // the binary as a process (harness_test_support.hpp)

nlohmann::json last_json(const std::string& out) {
  const auto a = out.find('{'), b = out.rfind('}');
  return nlohmann::json::parse(out.substr(a, b - a + 1));
}

std::string scene_path() { return test::shipped_scene("flat_stroke.toml"); }

class Session_ : public sb::test::TempDirTest {
 protected:
  Session_() : TempDirTest("sb_session_") {}
};

Session sample_session() {
  Session s;
  s.scene = "scene.toml";
  s.backend = "grid";
  s.overrides = {"material.friction=0.55"};
  s.trajectory.samples = {{0.0, Vec3(0.1, 0.2, 0.3), 0}, {0.001, Vec3(1.0 / 3.0, 0.2, 0.29), 1}};
  s.forces = {{0.0, Vec3(0.0, 0.0, 0.0), 0.0},
              {0.001, Vec3(0.1, -0.2, 2.5), 0.003, Vec3(0.11, -0.21, 2.4), 1.0 / 3.0, Vec3(0.1, 1.0 / 7.0, -0.02)}};
  ToolSpec disk;
  disk.radius_m = 0.0213;
  disk.sides = 17;
  disk.rim.width_m = 0.007;
  disk.rim.forward_bias = 0.65;
  ToolSpec poly;
  poly.shape = ToolShape::Polygon;
  poly.polygon_m = {{0.0, 0.0}, {0.02, 0.0}, {0.01, 1.0 / 70.0}};
  poly.profile = BottomProfile::SphereCap;
  poly.sphere_radius_m = 0.04;
  ToolSpec pour;
  pour.shape = ToolShape::Pour;
  pour.radius_m = 0.03;
  pour.pour_volume_m3 = 2e-6;
  s.tools = {disk, poly, pour};
  s.stamps = {{0.5, {Vec2(0.3, std::numbers::pi / 10.0), 0.09 + 1e-17, 0.7853981633974483}, Vec2(0.6, 0.8), 0},
              {0.6, {Vec2(0.31, 0.32), 0.0899999, -2.0}, Vec2(-1.0 / 3.0, std::sqrt(8.0) / 3.0), 1},
              {0.7, {Vec2(0.2, 0.2), 0.12, 0.0}, Vec2(0.0, 0.0), 2}};
  return s;
}

TEST_F(Session_, RoundTripsBitForBit) {
  const Session s = sample_session();
  const fs::path file = dir_ / "s.csv";
  write_session(file, s);
  const Session r = read_session(file, "--replay");
  EXPECT_EQ(r.scene, s.scene);
  EXPECT_EQ(r.backend, s.backend);
  EXPECT_EQ(r.overrides, s.overrides);
  ASSERT_EQ(r.trajectory.samples.size(), 2u);
  EXPECT_EQ(r.trajectory.samples[1].position_m, s.trajectory.samples[1].position_m);
  EXPECT_EQ(r.trajectory.samples[1].buttons, 1u);
  ASSERT_EQ(r.forces.size(), 2u);
  EXPECT_EQ(r.forces[1].force_n, s.forces[1].force_n);
  EXPECT_EQ(r.forces[1].penetration_m, s.forces[1].penetration_m);
  EXPECT_EQ(r.forces[1].model_force_n, s.forces[1].model_force_n);
  EXPECT_EQ(r.forces[1].contact_fraction, s.forces[1].contact_fraction);
  EXPECT_EQ(r.forces[1].model_velocity_m_s, s.forces[1].model_velocity_m_s);
  ASSERT_EQ(r.tools.size(), 3u);
  ASSERT_EQ(r.stamps.size(), 3u);

  // The schedules agree exactly: same footprints, poses, directions.
  const StampSchedule a = session_schedule(s, ToolSpec{}), b = session_schedule(r, ToolSpec{});
  ASSERT_EQ(a.stamps.size(), b.stamps.size());
  for (std::size_t i = 0; i < a.stamps.size(); ++i) {
    const ToolStamp &x = a.stamps[i], &y = b.stamps[i];
    EXPECT_EQ(y.generation, i);
    EXPECT_EQ(x.pose.xy, y.pose.xy);
    EXPECT_EQ(x.pose.bottom_z, y.pose.bottom_z);
    EXPECT_EQ(x.pose.heading_rad, y.pose.heading_rad);
    EXPECT_EQ(x.motion_dir, y.motion_dir);
    EXPECT_EQ(x.footprint, y.footprint);
    EXPECT_EQ(x.profile, y.profile);
    EXPECT_EQ(x.sphere_radius_m, y.sphere_radius_m);
    EXPECT_EQ(x.rim.width_m, y.rim.width_m);
    EXPECT_EQ(x.rim.forward_bias, y.rim.forward_bias);
    EXPECT_EQ(x.pour_volume_m3, y.pour_volume_m3);
    EXPECT_EQ(x.pour_radius_m, y.pour_radius_m);
  }
  EXPECT_EQ(b.stamps[0].footprint.size(), 17u);
  EXPECT_TRUE(b.stamps[2].is_pour());

  // The session is also a replay file for --device replay:FILE.
  EXPECT_EQ(haptics::load_trajectory(file).samples.size(), 2u);
}

// Sessions recorded before the contact fraction and velocity (8 force columns), and before
// the model's force (5), still read: the columns they lack are 0.
TEST_F(Session_, ReadsTheOlderForceTables) {
  const std::string rest =
      "tool,shape,radius_m,size_x_m,size_y_m,sides,profile,sphere_radius_m,depth_m,rim_width_m,rim_forward_bias,"
      "pour_volume_m3,polygon_m\n0,disk,0.02,0,0,32,flat,0,0.01,0.01,0.5,0,\n"
      "stamp,t,x,y,bottom_z,heading_rad,dir_x,dir_y,tool\n";
  const Session with_model = parse_session(
      "t,fx,fy,fz,penetration_m,model_fx,model_fy,model_fz\n0.5,1,2,3,0.004,1.5,2.5,3.5\n" + rest, "old", "--replay");
  ASSERT_EQ(with_model.forces.size(), 1u);
  EXPECT_EQ(with_model.forces[0].force_n, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(with_model.forces[0].penetration_m, 0.004);
  EXPECT_EQ(with_model.forces[0].model_force_n, Vec3(1.5, 2.5, 3.5));
  EXPECT_EQ(with_model.forces[0].contact_fraction, 0.0);
  EXPECT_EQ(with_model.forces[0].model_velocity_m_s, Vec3::Zero());
  const Session oldest = parse_session("t,fx,fy,fz,penetration_m\n0.5,1,2,3,0.004\n" + rest, "old", "--replay");
  ASSERT_EQ(oldest.forces.size(), 1u);
  EXPECT_EQ(oldest.forces[0].penetration_m, 0.004);
  EXPECT_EQ(oldest.forces[0].model_force_n, Vec3::Zero());
}

TEST_F(Session_, ToolIndexReusesIdenticalTools) {
  Session s;
  ToolSpec a, b;
  b.radius_m = 0.03;
  EXPECT_EQ(session_tool_index(s, a), 0u);
  EXPECT_EQ(session_tool_index(s, b), 1u);
  EXPECT_EQ(session_tool_index(s, a), 0u);
  EXPECT_EQ(s.tools.size(), 2u);
}

std::string read_error(const fs::path& file) {
  try {
    read_session(file, "--replay");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST_F(Session_, MalformedFilesNameTheOptionLineAndColumn) {
  const fs::path file = dir_ / "bad.csv";
  std::ofstream(file) << "t,x,y,z,buttons\n0,0,0,0,0\n";
  std::string e = read_error(file);
  EXPECT_NE(e.find("--replay"), std::string::npos) << e;
  EXPECT_NE(e.find("not a session file"), std::string::npos) << e;

  write_session(file, sample_session());
  std::string text;
  {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto rewrite = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    std::ofstream(file) << t;
  };
  // The first stamp row names tool 9, which does not exist.
  const auto row = text.find("\n0,", text.find("\nstamp,") + 1);
  const auto row_end = text.find('\n', row + 1);
  const std::string first = text.substr(row, row_end - row);
  rewrite(first, first.substr(0, first.rfind(',')) + ",9");
  e = read_error(file);
  EXPECT_NE(e.find("column tool = 9"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.csv:"), std::string::npos) << e;
  rewrite("0,disk,", "0,hexagon,");
  e = read_error(file);
  EXPECT_NE(e.find("column shape"), std::string::npos) << e;
  EXPECT_THROW(read_session(dir_ / "none.csv", "--replay"), InputError);
}

// The simulation thread without a window: a replay device presses a disk 8 mm into flat
// sand and drags it 6 cm; the session is recorded. With erosion off, the recorded stamps
// replayed through the runner give the very same terrain (grid: bit for bit).
TEST_F(Session_, RecordedStampsReplayExactly) {
  const std::vector<std::string> no_erosion = {"erosion.max_passes_per_step=0", "erosion.relax_at_end=false"};
  const PreparedScene prepared = prepare_scene(load_scene(scene_path(), no_erosion));
  haptics::Trajectory t;
  const Vec2 a(0.30, 0.33), b(0.36, 0.36);
  for (int i = 0; i <= 120; ++i) {
    const double u = i / 120.0;
    const double down = std::min(1.0, u / 0.2);
    const Vec2 xy = a + std::max(0.0, (u - 0.2) / 0.8) * (b - a);
    t.samples.push_back({0.9 * u, Vec3(xy.x(), xy.y(), 0.105 - 0.013 * down), 0});
  }
  const haptics::DeviceLimits limits = scene_device_limits(prepared.initial, 8.0, 2000.0);
  haptics::ReplayDevice device(t, limits);
  haptics::PatchBuffer patches;
  haptics::ServoOptions options;
  options.realtime = false;
  haptics::ServoLoop servo(device, patches, options);
  Simulation sim(prepared, make_terrain("grid", prepared.scene, prepared.initial), patches, servo, "grid");
  SimControls c = sim.controls();
  c.erosion = false;
  sim.set_controls(c);
  const fs::path file = dir_ / "session.csv";
  sim.start_recording(file);
  servo.start();
  sim.start();
  for (int i = 0; i < 400 && !device.finished(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  servo.stop();
  sim.stop();
  ASSERT_TRUE(device.finished());
  EXPECT_EQ(sim.recording_error(), "");
  const SimTotals totals = sim.totals();
  EXPECT_GE(totals.stamps, 10u);
  EXPECT_LE(servo.stats().force_max_n, limits.max_force_n);
  EXPECT_GT(servo.stats().ticks_in_contact, 0u);
  EXPECT_NEAR(totals.volume_final_m3, totals.volume_initial_m3, 1e-12 * totals.volume_initial_m3);
  EXPECT_TRUE(sim.terrain().check().ok());

  const Session session = read_session(file, "--replay");
  EXPECT_EQ(session.stamps.size(), totals.stamps);
  EXPECT_GT(session.trajectory.samples.size(), 500u);
  EXPECT_EQ(session.forces.size(), session.trajectory.samples.size());
  // The drag (about 0.09 m/s): the model's velocity and contact fraction are recorded with its force.
  bool moving_in_sand = false;
  for (const SessionForce& f : session.forces)
    moving_in_sand |= f.contact_fraction > 0.0 && f.model_velocity_m_s.head<2>().norm() > 0.05;
  EXPECT_TRUE(moving_in_sand);
  EXPECT_EQ(session.backend, "grid");

  PreparedScene replay = prepared;
  replay.schedule = session_schedule(session, prepared.scene.tool);
  auto fresh = make_terrain("grid", prepared.scene, prepared.initial);
  const RunResult run = run_schedule(*fresh, replay);
  Raster live = prepared.raster_template;
  sim.terrain().sample(live);
  ASSERT_EQ(run.final_raster.values.size(), live.values.size());
  EXPECT_EQ(run.final_raster.values, live.values);
  EXPECT_EQ(run.volume_final, totals.volume_final_m3);
}

TEST_F(Session_, RunReplaysASessionOnBothBackEnds) {
  const fs::path file = dir_ / "s.csv";
  Session s = sample_session();
  s.overrides.clear();
  write_session(file, s);
  for (const std::string backend : {"grid", "tin"}) {
    const auto r = sandbench("run " + scene_path() + " --backend " + backend + " --replay " + file.string() +
                             " --json --out " + (dir_ / (backend + ".h5")).string());
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = last_json(r.out);
    EXPECT_EQ(j["stamps"], 3) << backend;
    EXPECT_EQ(j["replay"], file.string());
    EXPECT_EQ(j["backend"], backend);
    EXPECT_NEAR(j["volume_added"].get<double>(), 2e-6, 1e-15);
  }
}

TEST_F(Session_, BadReplayAndInteractiveOptionsExitTwoBeforeAnyWindow) {
  const std::string scene = scene_path();
  auto r = sandbench("run " + scene + " --backend grid --replay " + (dir_ / "none.csv").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--replay"), std::string::npos) << r.out;
  const fs::path traj = dir_ / "traj.csv";
  std::ofstream(traj) << "t,x,y,z,buttons\n0,0.3,0.3,0.1,0\n";
  r = sandbench("run " + scene + " --backend grid --replay " + traj.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("not a session file"), std::string::npos) << r.out;

  const std::string base = "interactive " + scene + " --backend grid ";
  r = sandbench(base + "--device joystick");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--device joystick"), std::string::npos) << r.out;
  r = sandbench(base + "--device replay:" + (dir_ / "none.csv").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--device replay:"), std::string::npos) << r.out;
  r = sandbench(base + "--device udp:0");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("port"), std::string::npos) << r.out;
  r = sandbench(base + "--device replay:" + traj.string() + " --frames -3");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--frames"), std::string::npos) << r.out;
  r = sandbench(base + "--device replay:" + traj.string() + " --stats " + (dir_ / "no" / "s.json").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--stats"), std::string::npos) << r.out;
  r = sandbench(base + "--device replay:" + traj.string() + " --max-force-n 0");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--max-force-n"), std::string::npos) << r.out;
  r = sandbench("interactive " + scene + " --backend hex");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "no"));
}

}  // namespace
}  // namespace sb
