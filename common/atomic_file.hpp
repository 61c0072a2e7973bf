#pragma once
// Whole-or-nothing output: write to a temporary name beside the target, rename on success,
// remove the temporary on any failure.
#include <filesystem>
#include <functional>

namespace sb {

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& write);

}  // namespace sb
