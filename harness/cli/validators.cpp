#include "harness/cli/validators.hpp"

#include <charconv>
#include <filesystem>

namespace sb::cli {

namespace {
namespace fs = std::filesystem;

bool whole_in(const std::string& text, int lo, int hi, int& v) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  return !text.empty() && r.ec == std::errc() && r.ptr == text.data() + text.size() && v >= lo && v <= hi;
}
}  // namespace

CLI::Validator output_file() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const fs::path p = text;
        if (p.has_parent_path() && !fs::is_directory(p.parent_path()))
          return "directory " + p.parent_path().string() + " does not exist";
        if (fs::is_directory(p)) return text + " is a directory; give a file name";
        return {};
      },
      "FILE");
}

CLI::Validator output_directory() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const fs::path p = fs::absolute(text);
        if (fs::exists(p) && !fs::is_directory(p)) return text + " exists and is not a directory";
        if (!fs::exists(p) && !fs::is_directory(p.parent_path()))
          return "directory " + p.parent_path().string() + " does not exist";
        return {};
      },
      "DIR");
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

std::pair<int, int> parse_image_size(const std::string& text) {
  const auto x = text.find('x');
  return {std::stoi(text.substr(0, x)), std::stoi(text.substr(x + 1))};
}

}  // namespace sb::cli
