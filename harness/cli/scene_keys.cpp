// `sandbench scene-keys [--markdown]`: every scene key with its type, default, allowed range
// and meaning, from the validator itself (common/scene.hpp: scene_keys()).
#include <algorithm>
#include <iostream>
#include <memory>

#include "common/scene.hpp"
#include "harness/cli/commands.hpp"

namespace sb::cli {

namespace {
void print_keys(bool markdown) {
  const std::vector<SceneKey> keys = scene_keys();
  if (markdown) {
    std::cout << "| key | type | default | allowed | meaning |\n|---|---|---|---|---|\n";
    for (const SceneKey& k : keys)
      std::cout << "| `" << k.key << "` | " << k.type << " | " << (k.default_text.empty() ? "—" : k.default_text)
                << " | " << k.allowed << " | " << k.meaning << " |\n";
    return;
  }
  std::size_t width = 0;
  for (const SceneKey& k : keys) width = std::max(width, k.key.size());
  for (const SceneKey& k : keys) {
    std::cout << k.key << std::string(width + 2 - k.key.size(), ' ') << k.type << ", default "
              << (k.default_text.empty() ? "none (required or derived)" : k.default_text) << ", allowed " << k.allowed
              << "\n"
              << std::string(width + 2, ' ') << k.meaning << "\n";
  }
}
}  // namespace

void add_scene_keys_command(CLI::App& app) {
  auto markdown = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("scene-keys", "List every scene key with its default, allowed range and meaning");
  cmd->add_flag("--markdown", *markdown, "Print a Markdown table");
  cmd->callback([markdown] { print_keys(*markdown); });
}

}  // namespace sb::cli
