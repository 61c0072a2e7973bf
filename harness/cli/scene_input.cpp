#include "harness/cli/scene_input.hpp"

#include "common/input_error.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

PreparedScene prepare_input(const std::string& scene, const std::vector<std::string>& unset,
                            const std::vector<std::string>& overrides, const std::string& replay) {
  Session session;
  std::vector<std::string> all = scene_overrides(unset, overrides);
  if (!replay.empty()) {
    session = read_session(replay, "--replay");
    if (session.stamps.empty()) throw InputError("--replay " + replay + ": the session has no stamps");
    all.insert(all.begin(), session.overrides.begin(), session.overrides.end());
  }
  PreparedScene prepared = prepare_scene(load_scene(scene, all));
  if (!replay.empty()) {
    validate_session(session, prepared.scene, "--replay " + replay);
    // Sessions record the tools' shapes and rims, not the displacement model: the scene's.
    for (ToolSpec& t : session.tools) t.rim.model = prepared.scene.tool.rim.model;
    prepared.schedule = session_schedule(session);
    prepared.scene.reference = ReferenceKind::None;
  }
  return prepared;
}

}  // namespace sb::cli
