#pragma once
// CLI11 validators and transformers shared by the subcommands. A value they refuse is a
// CLI::ValidationError: the message names the option and what it accepts, and main turns
// it into exit code 2 before anything is read or written.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <optional>
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

// An output file: new or a regular file to replace, in a writable directory that exists
// (output_path_problem). The commands check again against their inputs once they know them.
CLI::Validator output_file();
// An output directory: new (created with its missing parents) or existing
// (output_directory_problem).
CLI::Validator output_directory();
// "WxH", each a whole number in [lo, hi].
CLI::Validator image_size(int lo, int hi);
// --max-memory: a byte count, or a number with K, M, G or T (powers of 1024), > 0; e.g. 8G.
CLI::Validator memory_size();
// Adds --max-memory to a command that takes a scene; `bytes` is set when it is given.
void add_max_memory_option(CLI::App& cmd, std::optional<std::uint64_t>& bytes);
// Splits a WxH that image_size accepted.
std::pair<int, int> parse_image_size(const std::string& text);

}  // namespace sb::cli
