#include "harness/cli/scene_input.hpp"

#include "common/input_error.hpp"
#include "common/schedule.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/preflight.hpp"

namespace sb::cli {

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
  if (replay) validate_session(session, scene, "--replay " + in.replay);
  // Before anything is allocated: refuse what cannot fit, warn of what is large.
  std::vector<PlannedRun> runs;
  for (const Variant& v : variants) runs.push_back({v.backend, variant_scene(v, scene)});
  const std::uint64_t limit =
      preflight(estimate_resources(runs, replay ? session.stamps.size() : stroke_stamps(scene), replay), in.max_memory);

  PreparedScene prepared = prepare_scene(std::move(scene));
  prepared.memory_limit_bytes = limit;
  if (replay) {
    prepared.schedule = session_schedule(session);
    prepared.scene.reference = ReferenceKind::None;
    prepared.replay = true;
  }
  return prepared;
}

}  // namespace sb::cli
