#pragma once
// A small CSV reader for the replay and session files: one or more tables, each introduced by
// a header line (a line whose first field does not start like a number), '#' comment lines and
// blank lines skipped; a second table with the same header is refused. Cells are trimmed strings; conversions name the
// file, line and column on error (InputError). O(file size).
#include <cstdint>
#include <string>
#include <vector>

namespace sb::haptics {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // line number (from 1) of each row
  int header_line = 0;
};

struct CsvFile {
  std::string name;                   // for messages
  std::vector<std::string> comments;  // text of '#' lines, without the '#' and leading space
  std::vector<CsvTable> tables;       // in file order
  // The table whose header is exactly `header`, or nullptr.
  const CsvTable* find(const std::vector<std::string>& header) const;
};

CsvFile parse_csv_tables(const std::string& text, const std::string& name);
CsvFile read_csv_tables(const std::string& path);  // InputError when unreadable

// A finite decimal number, the whole string: [+-]digits[.digits][e[+-]digits]. Hex floats,
// inf, nan, spaces and trailing bytes (a NUL among them) are refused. False when it is not one.
bool parse_decimal(const std::string& text, double& value);

// Cell conversions, each reading the whole cell (decimal digits only): InputError
// "NAME:LINE: column COL = 'v' is not ..." on failure.
double csv_number(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col);
std::uint32_t csv_mask(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col);
std::size_t csv_index(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col);
// Refuses row `row` when its column `col` (value, the previous row's previous) goes back in time.
void csv_check_time_order(const CsvFile& f, const CsvTable& t, std::size_t row, std::size_t col, double previous,
                          double value);
[[noreturn]] void csv_fail(const CsvFile& f, int line, const std::string& what);

}  // namespace sb::haptics
