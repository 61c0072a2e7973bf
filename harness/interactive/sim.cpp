#include "harness/interactive/sim.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "common/format.hpp"
#include "common/metrics.hpp"

namespace sb {

namespace {

constexpr double kMinPenetration_m = 1e-4;       // shallower contact does not stamp
constexpr double kDisplayPeriod_s = 1.0 / 30.0;  // counters, and a whole mesh
constexpr double kTilePeriod_s = 1.0 / 60.0;     // changed tiles (a lattice's or a mesh's)
constexpr std::size_t kRecentSteps = 256;

double patch_margin(double reach_m) { return std::max(0.015, 0.5 * reach_m); }

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string material_override(const char* key, double v) {
  return "material." + std::string(key) + "=" + exact_number(v);
}

}  // namespace

Simulation::Simulation(const PreparedScene& prepared, std::unique_ptr<Terrain> terrain, haptics::PatchBuffer& patches,
                       haptics::ServoLoop& servo, std::string backend, bool tiles)
    : prepared_(prepared),
      terrain_(std::move(terrain)),
      patches_(patches),
      servo_(servo),
      backend_(std::move(backend)) {
  active_.material = prepared.scene.material;
  active_.tool = prepared.scene.tool;
  active_.erosion_passes = prepared.scene.erosion.max_passes_per_step;
  controls_ = active_;
  rule_ = ErosionRule::from(active_.material, prepared.scene.erosion.settle_tolerance_deg, prepared.scene.erosion.rule);
  params_ = haptics::ForceParams::from(active_.material, active_.tool);
  layout_ = haptics::PatchLayout::for_tool(params_.reach_m, patch_margin(params_.reach_m));
  haptics::reserve_patches(patches_, layout_.cells);
  recent_ms_.assign(kRecentSteps, 0.0);
  totals_.volume_initial_m3 = terrain_->volume();
  status_.volume_initial_m3 = totals_.volume_initial_m3;
  volume_m3_ = totals_.volume_initial_m3;
  const Aabb2 box = prepared.scene.domain.box();
  feed_ = std::make_unique<DisplayFeed>(*terrain_, prepared.initial(0.5 * (box.lo + box.hi)), box, tiles);
  publish_patch(prepared.scene.domain.box().lo + 0.5 * prepared.scene.domain.size_m);
  publish_display(true);
}

Simulation::~Simulation() { stop(); }

void Simulation::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void Simulation::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
  record_request_.store(0);
  if (recording_) end_recording();
  publish_display(true);  // the final surface, for a window that draws once more
  totals_.final_stats = terrain_->stats();
  totals_.volume_final_m3 = terrain_->volume();
  totals_.volume_tracked_m3 = volume_m3_;
}

SimControls Simulation::controls() const {
  std::lock_guard lock(mutex_);
  return controls_;
}

void Simulation::set_controls(const SimControls& c) {
  {
    std::lock_guard lock(mutex_);
    controls_ = c;
  }
  controls_changed_.store(true);
}

SimStatus Simulation::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

void Simulation::start_recording(const std::filesystem::path& file) {
  {
    std::lock_guard lock(mutex_);
    requested_file_ = file;
  }
  record_request_.store(1);
}

void Simulation::stop_recording() { record_request_.store(-1); }

SimTotals Simulation::totals() const { return totals_; }

std::string Simulation::recording_error() const {
  std::lock_guard lock(mutex_);
  return record_error_;
}

void Simulation::run() {
  while (!stop_.load(std::memory_order_relaxed)) step();
}

void Simulation::step() {
  haptics::TripleBuffer<haptics::ServoState>& in = servo_.to_simulation();
  in.update();
  const haptics::ServoState& s = in.front();

  bool republish = false;
  if (controls_changed_.exchange(false)) {
    {
      std::lock_guard lock(mutex_);
      active_ = controls_;
    }
    rule_ =
        ErosionRule::from(active_.material, prepared_.scene.erosion.settle_tolerance_deg, prepared_.scene.erosion.rule);
    params_ = haptics::ForceParams::from(active_.material, active_.tool, heading_rad_);
    active_set_ = 1;  // a new critical angle may unsettle the sand
    layout_ = haptics::PatchLayout::for_tool(params_.reach_m, patch_margin(params_.reach_m));
    republish = true;
  }
  if (const int r = record_request_.exchange(0); r > 0) {
    if (recording_) end_recording();
    begin_recording();
  } else if (r < 0 && recording_) {
    end_recording();
  }

  bool worked = false, changed = false;
  if (!active_.paused) {
    const double cpu_start_s = thread_cpu_seconds();
    Stopwatch sw;
    const bool stamped = maybe_stamp(s);
    const double tool_ms = 1e3 * sw.seconds();
    double erosion_ms = 0.0, simplify_ms = 0.0;
    if (active_.erosion && (stamped || active_set_ > 0)) {
      sw.restart();
      const ErosionReport er = terrain_->erode(rule_, ErosionBudget{active_.erosion_passes, active_.erosion_updates,
                                                                    !stamped, prepared_.scene.erosion.cascade});
      erosion_ms = 1e3 * sw.seconds();
      add_volume(er.volume_change_m3);
      active_set_ = er.active;
      totals_.erosion_updates += er.updates;
      changed |= er.transfers > 0;
    }
    if (active_.simplify && (stamped || changed)) {
      sw.restart();
      const SimplifyReport sr = terrain_->simplify(SimplifyParams{prepared_.scene.tin.alpha_flat_deg});
      simplify_ms = 1e3 * sw.seconds();
      add_volume(sr.volume_change_m3);
      changed |= sr.removed > 0;
    }
    changed |= stamped;
    worked = stamped || changed;
    if (worked) {
      const double total = tool_ms + erosion_ms + simplify_ms;
      totals_.step_ms.push_back(total);
      totals_.step_cpu_ms.push_back(1e3 * (thread_cpu_seconds() - cpu_start_s));
      ++totals_.steps;
      recent_ms_[recent_next_++ % kRecentSteps] = total;
      std::lock_guard lock(mutex_);
      status_.tool_ms = tool_ms;
      status_.erosion_ms = erosion_ms;
      status_.simplify_ms = simplify_ms;
    }
  }
  dirty_ |= changed;

  // Republish the patch when the sand changed, the tool or material changed, or the tool
  // has used a third of the patch's margin.
  const Vec2 tool_xy = s.device.valid ? Vec2(s.device.position_m.head<2>()) : patch_centre_;
  const double margin = layout_.half_m - params_.reach_m;
  if (changed || republish || (tool_xy - patch_centre_).norm() > margin / 3.0) {
    publish_patch(tool_xy);
    worked = true;
  }
  if (recording_) drain_samples();
  publish_display(false);
  if (!worked) std::this_thread::sleep_for(std::chrono::microseconds(500));
}

bool Simulation::maybe_stamp(const haptics::ServoState& s) {
  if (!s.device.valid) return false;
  const Vec3 p = s.device.position_m;
  const Vec2 xy = p.head<2>();
  const ToolSpec& tool = active_.tool;
  const double spacing = prepared_.scene.stroke.spacing_m;
  const double moved = have_stamp_ ? (xy - last_stamp_xy_).norm() : 0.0;
  Vec2 dir = Vec2::Zero();

  if (tool.shape == ToolShape::Pour) {
    // Pour while the primary button is held: every spacing of motion, or every 0.1 s.
    if (!(s.device.buttons & 1u)) return false;
    if (have_stamp_ && moved < spacing && s.t_s - last_stamp_t_ < 0.1) return false;
  } else {
    if (!s.model.in_contact || s.model.penetration_m < kMinPenetration_m) return false;
    const double deeper = last_stamp_z_ - p.z();
    if (have_stamp_ && moved < spacing && deeper < 0.5 * spacing) return false;
    const Vec2 v = s.velocity_m_s.head<2>();
    if (have_stamp_ && moved > 1e-9 && moved <= 4.0 * spacing) {
      dir = (xy - last_stamp_xy_) / moved;
    } else if (v.norm() > 1e-3) {
      dir = v.normalized();
    }
    if (dir.squaredNorm() > 0.0) heading_rad_ = std::atan2(dir.y(), dir.x());
  }

  ToolPose pose;
  pose.xy = xy;
  pose.bottom_z = p.z();
  pose.heading_rad = tool.shape == ToolShape::Pour ? 0.0 : heading_rad_;
  const ToolStamp stamp = make_stamp(tool, pose, dir, generation_++);
  add_volume(terrain_->stamp(stamp).volume_change_m3);
  stamp_times_s_.push_back(steady_seconds());
  if (stamp.is_pour()) totals_.volume_added_m3 += stamp.pour_volume_m3;
  ++totals_.stamps;
  have_stamp_ = true;
  last_stamp_xy_ = xy;
  last_stamp_z_ = p.z();
  last_stamp_t_ = s.t_s;
  if (params_.heading_rad != heading_rad_) params_.heading_rad = heading_rad_;
  if (recording_) session_.stamps.push_back({s.t_s, pose, dir, session_tool_index(session_, tool)});
  return true;
}

void Simulation::publish_patch(const Vec2& centre) {
  Stopwatch sw;
  haptics::fill_patch(*terrain_, centre, layout_, params_, ++patch_version_, patches_.back());
  patches_.publish();
  patch_centre_ = centre;
  const double ms = 1e3 * sw.seconds();
  totals_.patch_ms.push_back(ms);
  ++totals_.patches;
  std::lock_guard lock(mutex_);
  status_.patch_ms = ms;
}

void Simulation::add_volume(double change_m3) {
  // A back-end that does not track a phase's change (NaN) is measured instead.
  if (std::isnan(change_m3)) {
    volume_m3_ = terrain_->volume();
  } else {
    volume_m3_ += change_m3;
  }
}

void Simulation::publish_display(bool force) {
  const double now = clock_.seconds();
  const bool by_tiles = feed_->lattice() || feed_->mesh_tiles() > 0;
  const double period = by_tiles ? kTilePeriod_s : kDisplayPeriod_s;
  // Changed tiles cost what changed, so a stamp is published at once: waiting for the period
  // would add up to a period to its latency. A mesh is rebuilt whole, at most once a period.
  const bool stamp_waiting = by_tiles && !stamp_times_s_.empty();
  if (force || (dirty_ && (stamp_waiting || now - last_surface_s_ >= period))) {
    Stopwatch sw;
    if (feed_->publish(*terrain_, dirty_ || force, stamp_times_s_)) totals_.display_ms.push_back(1e3 * sw.seconds());
    dirty_ = false;
    last_surface_s_ = now;
  }
  if (!force && now - last_status_s_ < kDisplayPeriod_s) return;
  const ModelStats stats = terrain_->stats();
  std::vector<double> recent(recent_ms_.begin(), recent_ms_.begin() + std::min(recent_next_, kRecentSteps));
  const double p50 = percentile(recent, 0.5), p95 = percentile(recent, 0.95);
  std::lock_guard lock(mutex_);
  status_.stats = stats;
  status_.volume_m3 = volume_m3_;
  status_.volume_added_m3 = totals_.volume_added_m3;
  status_.steps = totals_.steps;
  status_.stamps = totals_.stamps;
  status_.patches = totals_.patches;
  status_.step_ms_p50 = p50;
  status_.step_ms_p95 = p95;
  status_.recording = recording_;
  status_.tool_heading_rad = heading_rad_;
  status_.recorded_samples = session_.trajectory.samples.size();
  status_.recorded_stamps = session_.stamps.size();
  last_status_s_ = now;
}

void Simulation::drain_samples() {
  haptics::ServoSample r;
  while (servo_.samples().pop(r)) {
    if (!recording_ || !r.valid) continue;
    session_.trajectory.samples.push_back({r.t_s, r.position_m, r.buttons});
    session_.forces.push_back(
        {r.t_s, r.force_n, r.penetration_m, r.model_force_n, r.contact_fraction, r.model_velocity_m_s});
  }
}

void Simulation::begin_recording() {
  recording_ = false;
  drain_samples();  // discard anything queued before now
  recording_ = true;
  session_ = Session{};
  session_.scene = prepared_.scene.path;
  session_.backend = backend_;
  {
    std::lock_guard lock(mutex_);
    record_file_ = requested_file_;
    status_.recording = true;
    status_.message = "recording to " + record_file_.string();
  }
  servo_.set_recording(true);
}

void Simulation::end_recording() {
  servo_.set_recording(false);
  drain_samples();
  recording_ = false;
  const Material& m = active_.material;
  const Material& scene = prepared_.scene.material;
  session_.overrides.clear();
  if (m.critical_angle_deg != scene.critical_angle_deg)
    session_.overrides.push_back(material_override("critical_angle_deg", m.critical_angle_deg));
  if (m.transfer_fraction != scene.transfer_fraction)
    session_.overrides.push_back(material_override("transfer_fraction", m.transfer_fraction));
  if (m.stiffness_n_per_m != scene.stiffness_n_per_m)
    session_.overrides.push_back(material_override("stiffness_n_per_m", m.stiffness_n_per_m));
  if (m.drag_n_s_per_m != scene.drag_n_s_per_m)
    session_.overrides.push_back(material_override("drag_n_s_per_m", m.drag_n_s_per_m));
  if (m.friction != scene.friction) session_.overrides.push_back(material_override("friction", m.friction));
  std::string message, error;
  try {
    write_session(record_file_, session_);
    message = "wrote " + record_file_.string() + " (" + std::to_string(session_.stamps.size()) + " stamps, " +
              std::to_string(session_.trajectory.samples.size()) + " samples)";
  } catch (const std::exception& e) {
    error = e.what();
    message = "recording not written: " + error;
  }
  std::lock_guard lock(mutex_);
  status_.recording = false;
  status_.message = message;
  if (!error.empty()) record_error_ = error;
}

}  // namespace sb
