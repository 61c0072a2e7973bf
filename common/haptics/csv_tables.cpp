#include "common/haptics/csv_tables.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/input_error.hpp"

namespace sb::haptics {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

bool parses_as_number(const std::string& s) {
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end && *end == '\0';
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

}  // namespace

const CsvTable* CsvFile::find(const std::vector<std::string>& header) const {
  for (const CsvTable& t : tables)
    if (t.header == header) return &t;
  return nullptr;
}

void csv_fail(const CsvFile& f, int line, const std::string& what) {
  throw InputError(f.name + ":" + std::to_string(line) + ": " + what);
}

CsvFile parse_csv_tables(const std::string& text, const std::string& name) {
  CsvFile f;
  f.name = name;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  while (std::getline(in, raw)) {
    ++line;
    const std::string s = trim(raw);
    if (s.empty()) continue;
    if (s[0] == '#') {
      f.comments.push_back(trim(s.substr(1)));
      continue;
    }
    std::vector<std::string> cells = split(s);
    if (!parses_as_number(cells[0])) {
      CsvTable t;
      t.header = std::move(cells);
      t.header_line = line;
      f.tables.push_back(std::move(t));
      continue;
    }
    if (f.tables.empty()) csv_fail(f, line, "data before any header line");
    CsvTable& t = f.tables.back();
    if (cells.size() != t.header.size())
      csv_fail(f, line,
               "has " + std::to_string(cells.size()) + " fields; the header " + join(t.header) + " has " +
                   std::to_string(t.header.size()));
    t.rows.push_back(std::move(cells));
    t.lines.push_back(line);
  }
  return f;
}

CsvFile read_csv_tables(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_csv_tables(text.str(), path);
}

double csv_number(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  // ERANGE also flags underflow (a denormal like 5e-324, which recorded sessions can hold):
  // only an overflow to infinity is refused.
  const bool overflow = errno == ERANGE && std::fabs(v) > 1.0;
  if (s.empty() || *end != '\0' || overflow || !std::isfinite(v))
    csv_fail(f, t.lines[row], "column " + t.header[col] + " = '" + s + "' is not a finite number");
  return v;
}

std::uint32_t csv_mask(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || s[0] == '-' || *end != '\0' || errno == ERANGE || v > 0xffffffffULL)
    csv_fail(f, t.lines[row], "column " + t.header[col] + " = '" + s + "' is not an integer in [0, 4294967295]");
  return static_cast<std::uint32_t>(v);
}

std::size_t csv_index(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || s[0] == '-' || *end != '\0' || errno == ERANGE || v > 1000000000ULL)
    csv_fail(f, t.lines[row], "column " + t.header[col] + " = '" + s + "' is not an integer in [0, 1e9]");
  return static_cast<std::size_t>(v);
}

}  // namespace sb::haptics
