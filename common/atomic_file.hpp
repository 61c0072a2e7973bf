#pragma once
// Whole-or-nothing output: write to a temporary name beside the target, rename on success,
// remove the temporary on any failure. And the checks an output path passes before any work
// is done, so that a run never ends by destroying its input or a special file.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace sb {

// Temporaries are named TARGET.tmpPID. Before writing, temporaries of TARGET left by killed
// processes (PID no longer running) are removed. O(entries in the target's directory).
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& write);

// Throws InputError (prefixed by `option`, e.g. "--out") unless `target` can be written as a
// new or replaced regular file: non-empty; its directory exists; it is not a directory, a
// device, a FIFO, a socket or a symbolic link; and it is none of `inputs` (compared as files,
// so another spelling or a hard link of an input is caught too).
void check_output_path(const std::filesystem::path& target, const std::string& option,
                       const std::vector<std::filesystem::path>& inputs = {});

// The same for an output directory (compare --out): it may exist only as a directory, and its
// missing parents (created with it) must not run into a file.
void check_output_directory(const std::filesystem::path& target, const std::string& option,
                            const std::vector<std::filesystem::path>& inputs = {});

}  // namespace sb
