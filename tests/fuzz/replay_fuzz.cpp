// libFuzzer target: the replay and session CSV readers. Any input either reads into a
// trajectory or session whose numbers are finite and whose times never go back, or raises
// InputError; nothing else (no crash, no other exception, no sanitizer report).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/haptics/csv_tables.hpp"
#include "common/haptics/trajectory.hpp"
#include "common/input_error.hpp"
#include "harness/io/session_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sb::haptics::Trajectory t = sb::haptics::trajectory_from(sb::haptics::parse_csv_tables(text, "fuzz"));
    for (std::size_t i = 0; i < t.samples.size(); ++i) {
      if (!std::isfinite(t.samples[i].t_s) || !t.samples[i].position_m.allFinite()) __builtin_trap();
      if (i > 0 && t.samples[i].t_s < t.samples[i - 1].t_s) __builtin_trap();
    }
  } catch (const sb::InputError&) {
  }
  try {
    const sb::Session s = sb::parse_session(text, "fuzz", "--replay");
    for (std::size_t i = 0; i < s.stamps.size(); ++i) {
      if (s.stamps[i].tool >= s.tools.size() || !std::isfinite(s.stamps[i].t_s)) __builtin_trap();
      if (i > 0 && s.stamps[i].t_s < s.stamps[i - 1].t_s) __builtin_trap();
    }
  } catch (const sb::InputError&) {
  }
  return 0;
}
