#include "common/haptics/csv_tables.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
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

// A line is data when its first cell starts like a number (digits, sign, point, or a word
// strtod reads, such as inf or nan): those are then parsed strictly and refused with a message,
// never taken for the header of another table.
bool starts_like_number(const std::string& s) {
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end != s.c_str() || s.find_first_of("0123456789+-.") == 0;
}

bool all_digits(const std::string& s, std::size_t from) {
  return from < s.size() && s.find_first_not_of("0123456789", from) == std::string::npos;
}

// The cell as it can be printed: control bytes (a NUL among them) as \xNN.
std::string printable(const std::string& s) {
  std::string out;
  for (const unsigned char c : s) {
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out.push_back(static_cast<char>(c));
    }
  }
  return out;
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
    if (!starts_like_number(cells[0])) {
      for (const CsvTable& earlier : f.tables)
        if (earlier.header == cells)
          csv_fail(f, line,
                   "a second table with the header " + printable(join(cells)) + " (the first is at line " +
                       std::to_string(earlier.header_line) + "); a file holds each table once");
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

bool parse_decimal(const std::string& s, double& value) {
  // [+-] digits [. digits] [(e|E) [+-] digits], with digits on at least one side of the point.
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  const std::size_t int_begin = i;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
  std::size_t digits = i - int_begin;
  if (i < s.size() && s[i] == '.') {
    const std::size_t frac_begin = ++i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    digits += i - frac_begin;
  }
  if (digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (!all_digits(s, i)) return false;
    i = s.size();
  }
  if (i != s.size()) return false;  // trailing bytes, a NUL among them
  errno = 0;
  const double v = std::strtod(s.c_str(), nullptr);
  // ERANGE also flags underflow (a denormal like 5e-324, which recorded sessions can hold):
  // only an overflow to infinity is refused.
  if ((errno == ERANGE && std::fabs(v) > 1.0) || !std::isfinite(v)) return false;
  value = v;
  return true;
}

double csv_number(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  double v = 0.0;
  if (!parse_decimal(s, v))
    csv_fail(f, t.lines[row],
             "column " + t.header[col] + " = '" + printable(s) + "' is not a finite decimal number (e.g. -1.5e-3)");
  return v;
}

void csv_check_time_order(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col, double previous,
                          double value) {
  if (row > 0 && value < previous)
    csv_fail(f, t.lines[row],
             "column " + t.header[col] + " = " + t.rows[row][col] +
                 " goes back in time (previous row: " + t.rows[row - 1][col] + ")");
}

std::uint32_t csv_mask(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  errno = 0;
  const unsigned long long v = all_digits(s, 0) ? std::strtoull(s.c_str(), nullptr, 10) : 0;
  if (!all_digits(s, 0) || errno == ERANGE || v > 0xffffffffULL)
    csv_fail(f, t.lines[row],
             "column " + t.header[col] + " = '" + printable(s) + "' is not an integer in [0, 4294967295]");
  return static_cast<std::uint32_t>(v);
}

std::size_t csv_index(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col) {
  const std::string& s = t.rows[row][col];
  errno = 0;
  const unsigned long long v = all_digits(s, 0) ? std::strtoull(s.c_str(), nullptr, 10) : 0;
  if (!all_digits(s, 0) || errno == ERANGE || v > 1000000000ULL)
    csv_fail(f, t.lines[row], "column " + t.header[col] + " = '" + printable(s) + "' is not an integer in [0, 1e9]");
  return static_cast<std::size_t>(v);
}

}  // namespace sb::haptics
