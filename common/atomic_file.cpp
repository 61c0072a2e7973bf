#include "common/atomic_file.hpp"

#include <unistd.h>

#include <string>

namespace sb {

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path&)>& write) {
  std::filesystem::path temporary = target;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    write(temporary);
    std::filesystem::rename(temporary, target);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

}  // namespace sb
