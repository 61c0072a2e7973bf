#include "harness/cli/scene_input.hpp"

#include "common/input_error.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

void add_scene_options(CLI::App* cmd, SceneInput& in, ReplayOption replay) {
  cmd->add_option("scene", in.scene, "Scene file (TOML)")->required();
  cmd->add_option("--set", in.overrides, "Override a scene key: --set tool.radius_m=0.03")->take_all();
  cmd->add_option("--unset", in.unset, "Remove a scene key (before --set): --unset tool.radius_m")->take_all();
  if (replay == ReplayOption::With)
    cmd->add_option("--replay", in.replay,
                    "Replay a session recorded by `sandbench interactive --record`: its stamps are the schedule "
                    "(on every back-end)");
}

PreparedScene prepare_input(const SceneInput& in) {
  Session session;
  std::vector<std::string> all = scene_overrides(in.unset, in.overrides);
  if (!in.replay.empty()) {
    session = read_session(in.replay, "--replay");
    if (session.stamps.empty()) throw InputError("--replay " + in.replay + ": the session has no stamps");
    all.insert(all.begin(), session.overrides.begin(), session.overrides.end());
  }
  PreparedScene prepared = prepare_scene(load_scene(in.scene, all));
  if (!in.replay.empty()) {
    validate_session(session, prepared.scene, "--replay " + in.replay);
    // Sessions record the tools' shapes and rims, not the displacement model: the scene's.
    for (ToolSpec& t : session.tools) t.rim.model = prepared.scene.tool.rim.model;
    prepared.schedule = session_schedule(session);
    prepared.scene.reference = ReferenceKind::None;
  }
  return prepared;
}

}  // namespace sb::cli
