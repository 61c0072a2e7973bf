#pragma once
// Whole-or-nothing output: write to a temporary name beside the target, rename on success,
// remove the temporary on any failure. And the checks an output path passes before any work
// is done, so that a run never ends by destroying its input or a special file.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace sb {

// Temporaries are named TARGET.tmpPID. Before writing, temporaries of TARGET left by killed
// processes (PID no longer running) are removed. O(entries in the target's directory).
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& write);
// The same for a text (or any bytes) held in memory; a failed write (disk full, quota) is an
// InputError naming the file and the system's reason, and leaves nothing behind.
void write_text_atomically(const std::filesystem::path& target, std::string_view text);

// Why `target` cannot be written as a new or replaced regular file, or "" when it can: it must
// be non-empty; its directory must exist and be writable; it must not be a directory, a
// device, a FIFO, a socket or a symbolic link; and it must be none of `inputs` (compared as
// files, so another spelling or a hard link of an input is caught too). The CLI's validators
// and the commands (which know their inputs) share it.
std::string output_path_problem(const std::filesystem::path& target,
                                const std::vector<std::filesystem::path>& inputs = {});
// The same for an output directory (compare --out): it may exist only as a directory, and its
// missing parents (created with it) must not run into a file.
std::string output_directory_problem(const std::filesystem::path& target,
                                     const std::vector<std::filesystem::path>& inputs = {});

// Throw InputError "OPTION: problem" (e.g. "--out: ...") when the problem above is not "".
void check_output_path(const std::filesystem::path& target, const std::string& option,
                       const std::vector<std::filesystem::path>& inputs = {});
void check_output_directory(const std::filesystem::path& target, const std::string& option,
                            const std::vector<std::filesystem::path>& inputs = {});

}  // namespace sb
