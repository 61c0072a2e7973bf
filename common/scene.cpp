#include "common/scene.hpp"

#include <toml++/toml.h>

#include <fstream>
#include <sstream>

#include "common/input_error.hpp"
#include "common/scene_keys.hpp"
#include "common/scene_sections.hpp"

namespace sb {

std::string to_string(TerrainKind k) {
  switch (k) {
    case TerrainKind::Flat:
      return "flat";
    case TerrainKind::Dunes:
      return "dunes";
    case TerrainKind::Heightmap:
      return "heightmap";
    case TerrainKind::Plane:
      return "plane";
    case TerrainKind::Cone:
      return "cone";
  }
  return "?";
}

std::string to_string(ReferenceKind k) {
  switch (k) {
    case ReferenceKind::None:
      return "none";
    case ReferenceKind::Pile:
      return "pile";
    case ReferenceKind::Crater:
      return "crater";
    case ReferenceKind::Trench:
      return "trench";
    case ReferenceKind::Ridge:
      return "ridge";
    case ReferenceKind::Plane:
      return "plane";
  }
  return "?";
}

namespace {

using scene_detail::Fields;

// "unset KEY" (what --unset KEY adds) removes a key, so that a default applies again or a
// key that belongs to another tool shape goes away.
void apply_unset(toml::table& root, const std::string& key) {
  toml::table* t = &root;
  std::size_t start = 0;
  for (std::size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
    toml::node* child = t->get(key.substr(start, dot - start));
    t = child ? child->as_table() : nullptr;
    if (!t) return;  // nothing to remove
  }
  t->erase(key.substr(start));
}

void apply_override(toml::table& root, const std::string& assignment) {
  if (assignment.rfind(kUnsetPrefix, 0) == 0) {
    const std::string key = assignment.substr(std::string(kUnsetPrefix).size());
    if (key.empty() || key.find_first_of(" =") != std::string::npos)
      throw InputError("--unset " + key + ": expected a key, e.g. tool.radius_m");
    apply_unset(root, key);
    return;
  }
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + assignment + ": expected key=value, e.g. tool.radius_m=0.02");
  const std::string key = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  // The value is TOML ("0.02", "[1, 2]", "true", "\"disk\""); a bare word is a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", value}};
  }
  toml::table* t = &root;
  std::size_t start = 0;
  for (std::size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
    const std::string part = key.substr(start, dot - start);
    toml::node* child = t->get(part);
    if (!child) {
      t->insert(part, toml::table{});
      child = t->get(part);
    }
    t = child->as_table();
    if (!t) throw InputError("--set " + assignment + ": " + key.substr(0, dot) + " is not a table");
  }
  t->insert_or_assign(key.substr(start), std::move(*parsed.get("v")));
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides,
                  const std::filesystem::path& base_dir) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << name << ":" << e.source().begin.line << ":" << e.source().begin.column
        << ": not valid TOML: " << e.description();
    throw InputError(msg.str());
  }
  for (const auto& o : overrides) apply_override(root, o);

  Scene s;
  s.path = name;
  s.text = text;
  s.overrides = overrides;
  Fields fields(root);
  scene_detail::read_scene_sections(fields, s, base_dir);
  fields.reject_unknown();
  std::ostringstream resolved;
  resolved << root;
  s.resolved = resolved.str();
  return s;
}

std::string scene_crs(const std::string& resolved_text) {
  try {
    const toml::table root = toml::parse(resolved_text);
    return root.at_path("domain.crs").value_or(std::string());
  } catch (const toml::parse_error&) {
    return {};
  }
}

std::vector<SceneKey> scene_keys() {
  // One pass per terrain kind, tool shape and profile reaches every conditional key; the
  // passes run at two domain sizes so that ranges scaled by the domain are shown as such.
  const std::vector<std::vector<std::string>> variants = {
      {},
      {"terrain.kind=dunes"},
      {"terrain.kind=heightmap", "terrain.path=\"terrain.png\""},
      {"terrain.kind=plane"},
      {"terrain.kind=cone"},
      {"tool.shape=box", "tool.size_m=[0.04, 0.02]"},
      {"tool.shape=ellipse", "tool.size_m=[0.04, 0.02]"},
      {"tool.shape=polygon", "tool.polygon_m=[[0,0],[0.01,0],[0,0.01]]"},
      {"tool.shape=pour", "tool.volume_m3=1e-6"},
      {"tool.profile=sphere_cap"}};
  auto collect = [&](double extent) {
    std::vector<SceneKey> keys;
    // Backwards: a later pass's new keys go right after the key before them, so reading the
    // variants in reverse keeps the validator's order (dune keys before heightmap keys).
    for (auto it = variants.rbegin(); it != variants.rend(); ++it) {
      const auto& overrides = *it;
      std::ostringstream text;
      text << "[domain]\nsize_m = [" << extent << ", " << extent << "]\n[stroke]\npath_m = [[0.1, 0.1], [0.2, 0.2]]\n";
      toml::table root = toml::parse(text.str());
      for (const auto& o : overrides) apply_override(root, o);
      Scene scene;
      Fields fields(root, &keys);
      scene_detail::read_scene_sections(fields, scene, {});
    }
    return keys;
  };
  std::vector<SceneKey> keys = collect(1.0);
  const std::vector<SceneKey> doubled = collect(2.0);
  for (std::size_t i = 0; i < keys.size() && i < doubled.size(); ++i) {
    if (keys[i].allowed != doubled[i].allowed) keys[i].allowed += " x domain extent";
    if (keys[i].default_text != doubled[i].default_text) keys[i].default_text += " x domain extent";
    keys[i].meaning = scene_key_meaning(keys[i].key);
  }
  return keys;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("scene: cannot read " + file.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), file.string(), overrides, file.parent_path());
}

}  // namespace sb
