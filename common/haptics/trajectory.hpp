#pragma once
// A recorded device trajectory: the replay file of README "Interactive mode and haptics", CSV with the header
// t,x,y,z,buttons (seconds, metres, bit mask). Other tables after it (a session's tools and
// stamps) are ignored here. Parsing and writing are O(samples).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "common/geometry.hpp"
#include "common/haptics/csv_tables.hpp"

namespace sb::haptics {

struct TrajectorySample {
  double t_s = 0.0;
  Vec3 position_m{0.0, 0.0, 0.0};
  std::uint32_t buttons = 0;
};

struct Trajectory {
  std::vector<TrajectorySample> samples;  // t non-decreasing
  double duration_s() const { return samples.empty() ? 0.0 : samples.back().t_s - samples.front().t_s; }
};

inline const std::vector<std::string> kTrajectoryHeader{"t", "x", "y", "z", "buttons"};

// The t,x,y,z,buttons table of a parsed file; InputError (naming file and line) when it is
// missing, empty, has a non-finite value or time going backwards.
Trajectory trajectory_from(const CsvFile& file);
Trajectory load_trajectory(const std::filesystem::path& file);

// Writes the header and one row per sample, with round-trip precision.
void write_trajectory_table(std::ostream& out, const Trajectory& trajectory);

}  // namespace sb::haptics
