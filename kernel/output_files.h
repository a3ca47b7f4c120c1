// Files a command writes on request (--heatmap, --errmap, --json, --junit, --out): nothing that
// exists is overwritten unless --force says so, and an output is never one of the command's
// inputs, even with --force (`compare ref.exr test.exr --heatmap ref.exr` used to overwrite the
// reference it had just read).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace iblcheck {

// The same file: the same inode when both exist, else the same absolute, normalised path (through
// the symlinks of the folders that exist).
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// Throws UsageError naming `option` and `out` when `out` is one of `inputs` (whatever `force`
// says), or exists and `force` is false. Empty inputs are skipped.
void check_output_file(const std::filesystem::path& out, const std::string& option, bool force,
                       const std::vector<std::filesystem::path>& inputs = {});

// Throws UsageError naming both options when two outputs are the same file.
void check_distinct_outputs(const std::filesystem::path& a, const std::string& option_a, const std::filesystem::path& b,
                            const std::string& option_b);

// `rel` (relative to `dir`, or absolute) resolved, when the file it names lies inside `dir` once
// symlinks are resolved; else an empty path. A results file names its images relative to its
// folder; a tampered one must not make the report read (and copy into itself) any other file:
// `/home/u/.bashrc`, `../../../../etc/hostname`, or a symlink out of the folder.
std::filesystem::path inside_folder(const std::filesystem::path& dir, const std::string& rel);

} // namespace iblcheck
