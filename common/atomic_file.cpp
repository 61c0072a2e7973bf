#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "common/input_error.hpp"

namespace sb {

namespace fs = std::filesystem;

namespace {

// Removes TARGET.tmpPID files whose process is gone (a kill -9 leaves them behind).
void remove_stale_temporaries(const fs::path& target) {
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".tmp";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid()) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code ignored;
    if (fs::is_regular_file(fs::symlink_status(it->path(), ignored))) fs::remove(it->path(), ignored);
  }
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec) && !ec;
}

std::string kind_of(fs::file_type t) {
  switch (t) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::symlink:
      return "a symbolic link (give the path it points to)";
    case fs::file_type::block:
    case fs::file_type::character:
      return "a device";
    case fs::file_type::fifo:
      return "a FIFO";
    case fs::file_type::socket:
      return "a socket";
    case fs::file_type::regular:
      return "a regular file";
    default:
      return "not a regular file";
  }
}

void throw_if(const std::string& problem, const std::string& option) {
  if (!problem.empty()) throw InputError(option + ": " + problem);
}

}  // namespace

std::string output_path_problem(const fs::path& target, const std::vector<fs::path>& inputs) {
  if (target.empty()) return "the path is empty; give a file name";
  for (const fs::path& in : inputs)
    if (!in.empty() && same_file(target, in))
      return target.string() + " is the input " + in.string() + "; writing there would destroy it, choose another path";
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return "directory " + dir.string() + " (of " + target.string() + ") does not exist";
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return "directory " + dir.string() + " (of " + target.string() + ") is not writable";
  const fs::file_status st = fs::symlink_status(target, ec);
  if (fs::exists(st) && st.type() != fs::file_type::regular)
    return target.string() + " is " + kind_of(st.type()) + "; the output must be a regular file, new or to be replaced";
  // Writable by its mode is not enough (/proc, a read-only mount): try to create the temporary
  // file the write will use, and remove it again.
  const fs::path probe = fs::path(target.string() + ".tmp" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0 && errno != EEXIST) {
    // A directory that exists yet answers "no such file" is a pseudo-file system.
    const std::string why = errno == ENOENT ? "its file system does not allow new files (as /proc and /sys)"
                                            : std::string(std::strerror(errno));
    return "cannot create files in directory " + dir.string() + " (of " + target.string() + "): " + why +
           "; choose another directory";
  }
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  }
  return {};
}

std::string output_directory_problem(const fs::path& target, const std::vector<fs::path>& inputs) {
  // "out/" names the directory "out"; missing parents are created, like the directory.
  const fs::path dir = target.has_filename() ? target : target.parent_path();
  if (dir.empty()) return "the path is empty; give a directory name";
  for (const fs::path& in : inputs)
    if (!in.empty() && same_file(dir, in))
      return target.string() + " is the input " + in.string() + "; choose another path";
  std::error_code ec;
  for (fs::path up = dir.parent_path(); !up.empty(); up = up.parent_path()) {
    const fs::file_status parent = fs::status(up, ec);
    if (!fs::exists(parent)) {
      if (up == up.parent_path()) break;
      continue;
    }
    if (!fs::is_directory(parent)) return up.string() + " (in " + target.string() + ") is not a directory";
    break;
  }
  const fs::file_status st = fs::symlink_status(dir, ec);
  if (fs::exists(st) && st.type() != fs::file_type::directory)
    return target.string() + " is " + kind_of(st.type()) + "; the output must be a directory, new or existing";
  return {};
}

void check_output_path(const fs::path& target, const std::string& option, const std::vector<fs::path>& inputs) {
  throw_if(output_path_problem(target, inputs), option);
}

void check_output_directory(const fs::path& target, const std::string& option, const std::vector<fs::path>& inputs) {
  throw_if(output_directory_problem(target, inputs), option);
}

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  remove_stale_temporaries(target);
  fs::path temporary = target;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    write(temporary);
    fs::rename(temporary, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

void write_text_atomically(const fs::path& target, std::string_view text) {
  write_atomically(target, [&](const fs::path& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    // Disk full, quota, read-only: the user's to fix (exit 2), and nothing is left behind.
    if (!out)
      throw InputError("cannot write " + target.string() + " (" + std::strerror(errno) + "); nothing was written");
  });
}

}  // namespace sb
