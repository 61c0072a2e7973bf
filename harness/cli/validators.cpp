#include "harness/cli/validators.hpp"

#include <charconv>

#include "common/atomic_file.hpp"
#include "harness/run/preflight.hpp"

namespace sb::cli {

namespace {
bool whole_in(const std::string& text, int lo, int hi, int& v) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  return !text.empty() && r.ec == std::errc() && r.ptr == text.data() + text.size() && v >= lo && v <= hi;
}
}  // namespace

CLI::Validator output_file() {
  return CLI::Validator([](std::string& text) { return output_path_problem(text); }, "FILE");
}

CLI::Validator output_directory() {
  return CLI::Validator([](std::string& text) { return output_directory_problem(text); }, "DIR");
}

CLI::Validator image_size(int lo, int hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const auto x = text.find('x');
        int w = 0, h = 0;
        if (x == std::string::npos || !whole_in(text.substr(0, x), lo, hi, w) ||
            !whole_in(text.substr(x + 1), lo, hi, h))
          return "\"" + text + "\" must be WxH with W and H whole numbers in " + std::to_string(lo) + ".." +
                 std::to_string(hi) + ", e.g. 1024x768";
        return {};
      },
      "WxH");
}

CLI::Validator memory_size() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (!parse_memory_size(text))
          return "\"" + text + "\" must be a size in bytes > 0, optionally with K, M, G or T (e.g. 8G, 512M)";
        return {};
      },
      "SIZE");
}

void add_max_memory_option(CLI::App& cmd, std::optional<std::uint64_t>& bytes) {
  cmd.add_option_function<std::string>(
         "--max-memory", [&bytes](const std::string& text) { bytes = parse_memory_size(text); },
         "Refuse a run whose estimated memory exceeds this (bytes, or with K, M, G, T; default: the memory "
         "available)")
      ->check(memory_size());
}

std::pair<int, int> parse_image_size(const std::string& text) {
  const auto x = text.find('x');
  return {std::stoi(text.substr(0, x)), std::stoi(text.substr(x + 1))};
}

}  // namespace sb::cli
