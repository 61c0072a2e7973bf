#include "common/haptics/trajectory.hpp"

#include <cstdio>
#include <ostream>

namespace sb::haptics {

Trajectory trajectory_from(const CsvFile& file) {
  const CsvTable* t = file.find(kTrajectoryHeader);
  if (!t) {
    const int line = file.tables.empty() ? 1 : file.tables.front().header_line;
    csv_fail(file, line, "no table with the header t,x,y,z,buttons (a replay file is CSV with that header)");
  }
  if (t->rows.empty()) csv_fail(file, t->header_line, "the t,x,y,z,buttons table has no rows");
  Trajectory out;
  out.samples.reserve(t->rows.size());
  for (std::size_t r = 0; r < t->rows.size(); ++r) {
    TrajectorySample s;
    s.t_s = csv_number(file, *t, r, 0);
    s.position_m = {csv_number(file, *t, r, 1), csv_number(file, *t, r, 2), csv_number(file, *t, r, 3)};
    s.buttons = csv_mask(file, *t, r, 4);
    if (!out.samples.empty()) csv_check_time_order(file, *t, r, 0, out.samples.back().t_s, s.t_s);
    out.samples.push_back(s);
  }
  return out;
}

Trajectory load_trajectory(const std::filesystem::path& file) {
  return trajectory_from(read_csv_tables(file.string()));
}

void write_trajectory_table(std::ostream& out, const Trajectory& trajectory) {
  out << "t,x,y,z,buttons\n";
  char line[160];
  for (const TrajectorySample& s : trajectory.samples) {
    std::snprintf(line, sizeof line, "%.9f,%.17g,%.17g,%.17g,%u\n", s.t_s, s.position_m.x(), s.position_m.y(),
                  s.position_m.z(), s.buttons);
    out << line;
  }
}

}  // namespace sb::haptics
