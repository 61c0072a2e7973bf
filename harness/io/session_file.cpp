#include "harness/io/session_file.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <utility>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/haptics/csv_tables.hpp"
#include "common/input_error.hpp"

namespace sb {

namespace {

using haptics::csv_check_time_order;
using haptics::csv_fail;
using haptics::csv_index;
using haptics::csv_number;
using haptics::CsvFile;
using haptics::CsvTable;

const std::vector<std::string> kForceHeader{
    "t",        "fx",       "fy",      "fz", "penetration_m", "model_fx", "model_fy", "model_fz", "contact_fraction",
    "model_vx", "model_vy", "model_vz"};
// Sessions written before the contact fraction and velocity were recorded, and before the
// model's force was: each a prefix of the current header.
const std::vector<std::string> kForceHeaderWithoutContact(kForceHeader.begin(), kForceHeader.begin() + 8);
const std::vector<std::string> kForceHeaderWithoutModel(kForceHeader.begin(), kForceHeader.begin() + 5);
const std::vector<std::string> kToolHeader{
    "tool",    "shape",       "radius_m",         "size_x_m",       "size_y_m", "sides", "profile", "sphere_radius_m",
    "depth_m", "rim_width_m", "rim_forward_bias", "pour_volume_m3", "polygon_m"};
const std::vector<std::string> kStampHeader{"stamp",       "t",     "x",     "y",   "bottom_z",
                                            "heading_rad", "dir_x", "dir_y", "tool"};

// A tool's row without its index.
std::string tool_fields(const ToolSpec& t) {
  std::string poly;
  for (const Vec2& p : t.polygon_m) {
    if (!poly.empty()) poly += ' ';
    poly.append(exact_number(p.x())).append(" ").append(exact_number(p.y()));
  }
  return to_string(t.shape) + "," + exact_number(t.radius_m) + "," + exact_number(2.0 * t.half_size_m.x()) + "," +
         exact_number(2.0 * t.half_size_m.y()) + "," + std::to_string(t.sides) + "," + to_string(t.profile) + "," +
         exact_number(t.sphere_radius_m) + "," + exact_number(t.depth_m) + "," + exact_number(t.rim.width_m) + "," +
         exact_number(t.rim.forward_bias) + "," + exact_number(t.pour_volume_m3) + "," + poly;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

// A tool's row; the fields are checked by ToolSpec::problem(), as for every tool.
ToolSpec read_tool(const CsvFile& f, const CsvTable& t, std::size_t r) {
  ToolSpec tool;
  const int line = t.lines[r];
  const auto shape = tool_shape_from(t.rows[r][1]);
  if (!shape) csv_fail(f, line, "column shape = '" + t.rows[r][1] + "' must be disk | box | ellipse | polygon | pour");
  tool.shape = *shape;
  tool.radius_m = csv_number(f, t, r, 2);
  tool.half_size_m = Vec2(csv_number(f, t, r, 3), csv_number(f, t, r, 4)) / 2.0;
  const std::size_t sides = csv_index(f, t, r, 5);
  tool.sides = static_cast<int>(std::min<std::size_t>(sides, 1u << 30));
  const auto profile = bottom_profile_from(t.rows[r][6]);
  if (!profile) csv_fail(f, line, "column profile = '" + t.rows[r][6] + "' must be flat | sphere_cap");
  tool.profile = *profile;
  tool.sphere_radius_m = csv_number(f, t, r, 7);
  tool.depth_m = csv_number(f, t, r, 8);
  tool.rim.width_m = csv_number(f, t, r, 9);
  tool.rim.forward_bias = csv_number(f, t, r, 10);
  tool.pour_volume_m3 = csv_number(f, t, r, 11);
  std::istringstream poly(t.rows[r][12]);
  std::vector<double> xy;
  for (std::string w; poly >> w;) {
    double v = 0.0;
    if (!haptics::parse_decimal(w, v))
      csv_fail(f, line, "column polygon_m: '" + w + "' is not a finite decimal number");
    xy.push_back(v);
  }
  if (xy.size() % 2 != 0) csv_fail(f, line, "column polygon_m must hold x y pairs");
  for (std::size_t i = 0; i < xy.size(); i += 2) tool.polygon_m.emplace_back(xy[i], xy[i + 1]);
  if (const auto problem = tool.problem()) csv_fail(f, line, *problem);
  return tool;
}

}  // namespace

std::size_t session_tool_index(Session& session, const ToolSpec& tool) {
  const std::string row = tool_fields(tool);
  for (std::size_t i = 0; i < session.tools.size(); ++i)
    if (tool_fields(session.tools[i]) == row) return i;
  session.tools.push_back(tool);
  return session.tools.size() - 1;
}

void write_session(const std::filesystem::path& file, const Session& s) {
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError("--record " + file.string() + ": cannot write");
    out << "# sandbench session 1\n";
    if (!s.scene.empty()) out << "# scene: " << s.scene << "\n";
    if (!s.backend.empty()) out << "# backend: " << s.backend << "\n";
    for (const auto& o : s.overrides) out << "# set " << o << "\n";
    out << "# tables: device trajectory, forces, tools, stamps (README: Interactive mode and haptics)\n";
    // A session without device samples (stamps only) has no trajectory table: an empty one
    // would not read back.
    if (!s.trajectory.samples.empty()) haptics::write_trajectory_table(out, s.trajectory);
    if (!s.forces.empty()) {
      out << join(kForceHeader) << "\n";
      for (const SessionForce& f : s.forces)
        out << exact_number(f.t_s) << "," << exact_number(f.force_n.x()) << "," << exact_number(f.force_n.y()) << ","
            << exact_number(f.force_n.z()) << "," << exact_number(f.penetration_m) << ","
            << exact_number(f.model_force_n.x()) << "," << exact_number(f.model_force_n.y()) << ","
            << exact_number(f.model_force_n.z()) << "," << exact_number(f.contact_fraction) << ","
            << exact_number(f.model_velocity_m_s.x()) << "," << exact_number(f.model_velocity_m_s.y()) << ","
            << exact_number(f.model_velocity_m_s.z()) << "\n";
    }
    out << join(kToolHeader) << "\n";
    for (std::size_t i = 0; i < s.tools.size(); ++i) out << i << "," << tool_fields(s.tools[i]) << "\n";
    out << join(kStampHeader) << "\n";
    for (std::size_t i = 0; i < s.stamps.size(); ++i) {
      const SessionStamp& st = s.stamps[i];
      out << i << "," << exact_number(st.t_s) << "," << exact_number(st.pose.xy.x()) << ","
          << exact_number(st.pose.xy.y()) << "," << exact_number(st.pose.bottom_z) << ","
          << exact_number(st.pose.heading_rad) << "," << exact_number(st.motion_dir.x()) << ","
          << exact_number(st.motion_dir.y()) << "," << st.tool << "\n";
    }
    out.flush();
    if (!out) throw std::runtime_error("writing " + tmp.string() + " failed");
  });
}

namespace {
Session session_from(const CsvFile& f, const std::string& option);
}  // namespace

Session read_session(const std::filesystem::path& file, const std::string& option) {
  // The CSV reader holds the whole file as text and cells: bound it before reading.
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (!ec && bytes > kMaxSessionBytes)
    throw InputError(option + " " + file.string() + ": " + std::to_string(bytes) +
                     " bytes, more than a session may have (" + std::to_string(kMaxSessionBytes) + ")");
  CsvFile f;
  try {
    f = haptics::read_csv_tables(file.string());
  } catch (const InputError& e) {
    throw InputError(option + " " + e.what());
  }
  return session_from(f, option);
}

Session parse_session(const std::string& text, const std::string& name, const std::string& option) {
  CsvFile f;
  try {
    f = haptics::parse_csv_tables(text, name);
  } catch (const InputError& e) {
    throw InputError(option + " " + e.what());
  }
  return session_from(f, option);
}

namespace {

Session session_from(const CsvFile& f, const std::string& option) {
  try {
    Session s;
    for (const std::string& c : f.comments) {
      if (c.rfind("set ", 0) == 0) {
        const std::string o = c.substr(4);
        if (o.find('=') == std::string::npos)
          throw InputError(f.name + ": comment '# " + c + "' must be '# set key=value'");
        s.overrides.push_back(o);
      } else if (c.rfind("scene: ", 0) == 0) {
        s.scene = c.substr(7);
      } else if (c.rfind("backend: ", 0) == 0) {
        s.backend = c.substr(9);
      }
    }
    if (f.find(haptics::kTrajectoryHeader)) s.trajectory = haptics::trajectory_from(f);
    // The force table in the newest layout found; columns a file lacks stay 0.
    const CsvTable* forces = nullptr;
    std::size_t columns = 0;
    for (const auto* header : {&kForceHeader, &kForceHeaderWithoutContact, &kForceHeaderWithoutModel})
      if ((forces = f.find(*header))) {
        columns = header->size();
        break;
      }
    for (std::size_t r = 0; forces && r < forces->rows.size(); ++r) {
      auto cell = [&](std::size_t c) { return c < columns ? csv_number(f, *forces, r, c) : 0.0; };
      s.forces.push_back({cell(0),
                          {cell(1), cell(2), cell(3)},
                          cell(4),
                          {cell(5), cell(6), cell(7)},
                          cell(8),
                          {cell(9), cell(10), cell(11)}});
      if (r > 0) csv_check_time_order(f, *forces, r, 0, s.forces[r - 1].t_s, s.forces[r].t_s);
    }
    const CsvTable* tools = f.find(kToolHeader);
    const CsvTable* stamps = f.find(kStampHeader);
    if (!tools || !stamps)
      throw InputError(f.name + ": not a session file: it needs the tables '" + join(kToolHeader) + "' and '" +
                       join(kStampHeader) + "' (sandbench interactive --record writes them)");
    for (std::size_t r = 0; r < tools->rows.size(); ++r) {
      if (csv_index(f, *tools, r, 0) != r) csv_fail(f, tools->lines[r], "column tool must count 0, 1, 2, ...");
      s.tools.push_back(read_tool(f, *tools, r));
    }
    if (stamps->rows.size() > kMaxSessionStamps)
      throw InputError(f.name + ": " + std::to_string(stamps->rows.size()) + " stamps, more than a scene may have (" +
                       std::to_string(kMaxSessionStamps) + ")");
    for (std::size_t r = 0; r < stamps->rows.size(); ++r) {
      SessionStamp st;
      if (csv_index(f, *stamps, r, 0) != r) csv_fail(f, stamps->lines[r], "column stamp must count 0, 1, 2, ...");
      st.t_s = csv_number(f, *stamps, r, 1);
      if (r > 0) csv_check_time_order(f, *stamps, r, 1, s.stamps.back().t_s, st.t_s);
      st.pose.xy = {csv_number(f, *stamps, r, 2), csv_number(f, *stamps, r, 3)};
      st.pose.bottom_z = csv_number(f, *stamps, r, 4);
      st.pose.heading_rad = csv_number(f, *stamps, r, 5);
      st.motion_dir = {csv_number(f, *stamps, r, 6), csv_number(f, *stamps, r, 7)};
      st.tool = csv_index(f, *stamps, r, 8);
      // The ranges a scene's stroke has (stroke.path_m within domain.origin_m's range,
      // stroke.z_m), so a replay cannot ask for what a scene may not.
      for (std::size_t col : {2, 3, 4})
        if (!(std::fabs(csv_number(f, *stamps, r, col)) < kMaxCoordinate))
          csv_fail(f, stamps->lines[r],
                   "column " + stamps->header[col] + " = " + stamps->rows[r][col] + " is out of range (-1e9, 1e9)");
      if (st.motion_dir.norm() > 1.0 + 1e-9)
        csv_fail(f, stamps->lines[r], "columns dir_x, dir_y must be a unit vector or zero");
      if (st.tool >= s.tools.size())
        csv_fail(f, stamps->lines[r], "column tool = " + stamps->rows[r][8] + " names no row of the tool table");
      s.stamps.push_back(st);
    }
    return s;
  } catch (const InputError& e) {
    throw InputError(option + " " + e.what());
  }
}

// A session tool as scene overrides: the keys the scene format has for its shape.
std::vector<std::string> tool_overrides(const ToolSpec& t) {
  std::vector<std::string> o{unset_override("tool"), "tool.shape=\"" + to_string(t.shape) + "\""};
  const std::string size =
      "tool.size_m=[" + exact_number(2.0 * t.half_size_m.x()) + "," + exact_number(2.0 * t.half_size_m.y()) + "]";
  switch (t.shape) {
    case ToolShape::Disk:
      o.push_back("tool.radius_m=" + exact_number(t.radius_m));
      o.push_back("tool.sides=" + std::to_string(t.sides));
      break;
    case ToolShape::Pour:
      o.push_back("tool.radius_m=" + exact_number(t.radius_m));
      o.push_back("tool.volume_m3=" + exact_number(t.pour_volume_m3));
      return o;
    case ToolShape::Box:
      o.push_back(size);
      break;
    case ToolShape::Ellipse:
      o.push_back(size);
      o.push_back("tool.sides=" + std::to_string(t.sides));
      break;
    case ToolShape::Polygon: {
      std::string poly;
      for (const Vec2& p : t.polygon_m) {
        if (!poly.empty()) poly.push_back(',');
        poly.append("[").append(exact_number(p.x())).append(",").append(exact_number(p.y())).append("]");
      }
      o.push_back("tool.polygon_m=[" + poly + "]");
      break;
    }
  }
  o.push_back("tool.depth_m=" + exact_number(t.depth_m));
  o.push_back("tool.profile=\"" + to_string(t.profile) + "\"");
  if (t.profile == BottomProfile::SphereCap) o.push_back("tool.sphere_radius_m=" + exact_number(t.sphere_radius_m));
  o.push_back("tool.rim_width_m=" + exact_number(t.rim.width_m));
  o.push_back("tool.rim_forward_bias=" + exact_number(t.rim.forward_bias));
  return o;
}

}  // namespace

void validate_session(const Session& session, const Scene& scene, const std::string& option) {
  for (std::size_t i = 0; i < session.tools.size(); ++i) {
    std::vector<std::string> overrides = scene.overrides;
    const std::vector<std::string> tool = tool_overrides(session.tools[i]);
    overrides.insert(overrides.end(), tool.begin(), tool.end());
    try {
      parse_scene(scene.text, scene.path, overrides, std::filesystem::path(scene.path).parent_path());
    } catch (const InputError& e) {
      throw InputError(option + ": tool " + std::to_string(i) +
                       " of the session is not a valid tool for this scene: " + e.what());
    }
  }
  double corners = 0.0;
  for (const SessionStamp& st : session.stamps)
    corners += static_cast<double>(session.tools[st.tool].footprint_corners());
  if (corners > kMaxStampCorners)
    throw InputError(option + ": the session's " + std::to_string(session.stamps.size()) + " stamps have " +
                     exact_number(corners) + " footprint corners in all, more than a scene may ask for (" +
                     exact_number(kMaxStampCorners) + ")");
}

StampSchedule session_schedule(const Session& session, const ToolSpec& scene_tool) {
  // The poses are shared with the generator; footprints are built one stamp at a time.
  struct Poses {
    std::vector<SessionStamp> stamps;
    std::vector<ToolSpec> tools;
  };
  std::vector<ToolSpec> tools = session.tools;
  for (ToolSpec& t : tools) {
    t.rim.model = scene_tool.rim.model;
    t.rim.tan_repose = scene_tool.rim.tan_repose;
    t.rim.carry_shed_fraction = scene_tool.rim.carry_shed_fraction;
    t.rim.face_friction = scene_tool.rim.face_friction;
  }
  auto poses = std::make_shared<const Poses>(Poses{session.stamps, std::move(tools)});
  StampSchedule schedule;
  for (std::size_t i = 1; i < session.stamps.size(); ++i)
    schedule.length_m += (session.stamps[i].pose.xy - session.stamps[i - 1].pose.xy).norm();
  schedule.stamps = StampSequence(session.stamps.size(), [poses](std::size_t i) {
    const SessionStamp& st = poses->stamps[i];
    return make_stamp(poses->tools[st.tool], st.pose, st.motion_dir, static_cast<std::uint32_t>(i));
  });
  return schedule;
}

}  // namespace sb
