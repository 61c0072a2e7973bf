#include "harness/cli/scene_input.hpp"

#include "common/input_error.hpp"
#include "common/schedule.hpp"
#include "harness/cli/validators.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/preflight.hpp"

namespace sb::cli {

void add_scene_options(CLI::App* cmd, SceneInput& in, ReplayOption replay) {
  cmd->add_option("scene", in.scene, "Scene file (TOML)")->required();
  cmd->add_option("--set", in.overrides, "Override a scene key: --set tool.radius_m=0.03")->take_all();
  cmd->add_option("--unset", in.unset, "Remove a scene key (before --set): --unset tool.radius_m")->take_all();
  if (replay == ReplayOption::With) {
    cmd->add_option("--replay", in.replay,
                    "Replay a session recorded by `sandbench interactive --record`: its stamps are the schedule "
                    "(on every back-end)");
  }
  add_max_memory_option(*cmd, in.max_memory);
}

namespace {
// The scene's own stroke: its stamp count without building the schedule.
std::size_t stroke_stamps(const Scene& s) {
  return stamp_arc_count(polyline_length(s.stroke.path_m), s.stroke.spacing_m) *
         static_cast<std::size_t>(s.stroke.repeat);
}
}  // namespace

PreparedScene prepare_input(const SceneInput& in, const std::vector<Variant>& variants) {
  Session session;
  std::vector<std::string> all = scene_overrides(in.unset, in.overrides);
  const bool replay = !in.replay.empty();
  if (replay) {
    session = read_session(in.replay, "--replay");
    if (session.stamps.empty()) throw InputError("--replay " + in.replay + ": the session has no stamps");
    all.insert(all.begin(), session.overrides.begin(), session.overrides.end());
  }
  Scene scene = load_scene(in.scene, all);
  if (replay) {
    validate_session(session, scene, "--replay " + in.replay);
  }
  // Before anything is allocated: refuse what cannot fit, warn of what is large.
  std::vector<PlannedRun> runs;
  for (const Variant& v : variants) runs.push_back({v.backend, variant_scene(v, scene)});
  const std::uint64_t limit =
      preflight(estimate_resources(runs, replay ? session.stamps.size() : stroke_stamps(scene), replay), in.max_memory);

  PreparedScene prepared = prepare_scene(std::move(scene));
  prepared.memory_limit_bytes = limit;
  if (replay) {
    prepared.schedule = session_schedule(session, prepared.scene.tool);
    prepared.scene.reference = ReferenceKind::None;
    prepared.replay = true;
  }
  return prepared;
}

}  // namespace sb::cli
