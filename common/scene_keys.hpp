#pragma once
// The one-line meaning of each scene key, for `sandbench scene-keys` (common/scene.hpp:
// scene_keys() pairs them with the type, default and range the validator uses).
#include <string>

namespace sb {

// "" for a key with no entry (a unit test requires one for every key the validator reads).
std::string scene_key_meaning(const std::string& key);

}  // namespace sb
