#pragma once
// CLI11 validators and transformers shared by the subcommands. A value they refuse is a
// CLI::ValidationError: the message names the option and what it accepts, and main turns
// it into exit code 2 before anything is read or written.
#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <type_traits>

namespace sb::cli {

// An enum option given by name, any case: `--view top`. Anything else is refused with
// "\"side\" must be one of oblique | top".
template <typename Enum>
CLI::Validator names(const std::map<std::string, Enum>& table) {
  std::string list;
  for (const auto& entry : table) list += (list.empty() ? "" : " | ") + entry.first;
  return CLI::Validator(
      [table, list](std::string& text) -> std::string {
        const auto it = table.find(CLI::detail::to_lower(text));
        if (it == table.end()) return "\"" + text + "\" must be one of " + list;
        text = std::to_string(static_cast<std::underlying_type_t<Enum>>(it->second));  // CLI11 reads enums as numbers
        return {};
      },
      list);
}

// An output file: its directory must exist and it must not be a directory itself.
CLI::Validator output_file();
// An output directory: created if missing, so its parent must exist.
CLI::Validator output_directory();
// "WxH", each a whole number in [lo, hi].
CLI::Validator image_size(int lo, int hi);
// Splits a WxH that image_size accepted.
std::pair<int, int> parse_image_size(const std::string& text);

}  // namespace sb::cli
