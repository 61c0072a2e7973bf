#pragma once
// Session files: what `sandbench interactive --record FILE` writes and `sandbench run
// --replay FILE` (or `--device replay:FILE`) reads. One CSV file of tables, each introduced by
// its header line, after '#' comment lines:
//   # sandbench session 1 / # scene: ... / # backend: ... / # set key=value (scene overrides
//     the session made, e.g. material sliders; replay applies them before its own --set)
//   t,x,y,z,buttons                 the device trajectory (README: the replay format)
//   t,fx,fy,fz,penetration_m,model_fx,model_fy,model_fz,contact_fraction,model_vx,model_vy,model_vz
//     the force sent at each of those ticks, the model's force at the same pose
//     (ServoState::model_force_n), and what the model's force on the newest patch was
//     computed from besides the scene's parameters (penetration d, contact fraction c, the
//     velocity v: force_model.hpp); files without the last four columns still read (c and v
//     0), and so do files without the model's force (0 too)
//   tool,shape,radius_m,...         every tool used, in full
//   stamp,t,x,y,bottom_z,heading_rad,dir_x,dir_y,tool   every stamp applied, in order
// Numbers are written with round-trip precision, so replayed stamps are the recorded ones
// bit for bit. Reading and writing are O(file); writing is whole-or-nothing.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "common/haptics/trajectory.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "common/tool.hpp"

namespace sb {

struct SessionStamp {
  double t_s = 0.0;  // servo time when applied
  ToolPose pose;
  Vec2 motion_dir{0.0, 0.0};
  std::size_t tool = 0;  // index into Session::tools
};

struct SessionForce {
  double t_s = 0.0;
  Vec3 force_n{0.0, 0.0, 0.0};
  double penetration_m = 0.0;
  Vec3 model_force_n{0.0, 0.0, 0.0};       // the model's force at the same pose, blend included
  double contact_fraction = 0.0;           // c of the model on the newest patch
  Vec3 model_velocity_m_s{0.0, 0.0, 0.0};  // the velocity the model was evaluated with
};

struct Session {
  std::string scene;                   // informational
  std::string backend;                 // informational
  std::vector<std::string> overrides;  // "key=value"
  haptics::Trajectory trajectory;
  std::vector<SessionForce> forces;  // one per trajectory sample, or none
  std::vector<ToolSpec> tools;
  std::vector<SessionStamp> stamps;
};

void write_session(const std::filesystem::path& file, const Session& session);
// Throws InputError naming the file, line and column of anything malformed; `option` (e.g.
// "--replay") prefixes the message.
Session read_session(const std::filesystem::path& file, const std::string& option);
// The same from the file's text (`name` for messages).
Session parse_session(const std::string& text, const std::string& name, const std::string& option);

// Bounds on what a session file may hold (a scene's stroke may have at most 1e7 stamps).
inline constexpr std::size_t kMaxSessionStamps = 10000000;
inline constexpr std::uintmax_t kMaxSessionBytes = std::uintmax_t{256} << 20;  // about 2.5e6 stamp rows
inline constexpr double kMaxCoordinate = 1e9;

// Checks a session against the scene it is replayed on with the scene's own validation:
// every tool must pass as that scene's [tool] (ranges relative to the domain), and the stamp
// count times footprint corners must stay within kMaxStampCorners. Throws InputError
// prefixed by `option`. O(tools x scene parse + stamps).
void validate_session(const Session& session, const Scene& scene, const std::string& option);

// The stamps of a session as a lazy schedule (generations renumbered from 0): keeps a copy of
// the poses, O(stamps) small records; footprints are built when a stamp is asked for. Sessions
// record the tools' shapes and rims, not where a tool puts the sand it cuts: every tool takes
// the displacement model, its front pile's slope and its shed fraction of `scene_tool` (the scene replayed on,
// as the live session took them from its scene).
StampSchedule session_schedule(const Session& session, const ToolSpec& scene_tool);

// Adds `tool` to the session's tool table unless an identical one is there; its index.
std::size_t session_tool_index(Session& session, const ToolSpec& tool);

}  // namespace sb
