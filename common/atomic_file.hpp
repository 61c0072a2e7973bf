#pragma once
// Whole-or-nothing output: write to a temporary name beside the target, rename on success,
// remove the temporary on any failure.
#include <filesystem>
#include <functional>
#include <string_view>

namespace sb {

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& write);
// The same for a text (or any bytes) held in memory; throws std::runtime_error when the
// write fails.
void write_text_atomically(const std::filesystem::path& target, std::string_view text);

}  // namespace sb
