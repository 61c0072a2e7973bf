// libFuzzer target: scene parsing. Any input either parses into a valid scene or raises
// InputError; nothing else (no crash, no other exception, no sanitizer report).
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/input_error.hpp"
#include "common/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sb::Scene s = sb::parse_scene(text, "fuzz");
    // A valid scene must describe a non-empty domain and stroke.
    if (!(s.domain.size_m.minCoeff() > 0.0) || s.stroke.path_m.empty()) __builtin_trap();
  } catch (const sb::InputError&) {
  }
  return 0;
}
