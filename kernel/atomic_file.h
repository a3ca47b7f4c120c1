// Files written whole or not at all. The content goes to a temporary file beside the target, named
// for this process and thread (two writers never share one), which is then renamed over the target:
// a reader sees the old file or the new one, never half of one. On any failure the temporary file
// is removed. The folder must exist (the callers decide whether to create it). A target that exists
// and is not a regular file (a device, a FIFO) is written into, never replaced.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace iblcheck {

// The temporary name of `file` for this process and thread: FILE.tmp<pid>-<thread>.EXT, ending in the
// file's extension (the image writers pick the format by it).
std::filesystem::path temporary_path(const std::filesystem::path& file);

// Writes `bytes` (text or binary, as they are) to `file`. Throws InputError
// "FILE: cannot write[ WHAT]: REASON", `what` naming the content (e.g. "results JSON").
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes, const std::string& what = "");

// The same for a writer that takes a path (the EXR writer): `write(tmp)` writes the temporary file
// and throws on failure; its exception is rethrown after the temporary file is removed.
void write_file_atomically(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write,
                           const std::string& what = "");

// A cache entry (precomputes, counts, compiled shaders): written the same way, but a failure is no
// error: false, and nothing is left behind (the next run does the work again).
bool try_write_file_atomically(const std::filesystem::path& file, std::string_view bytes) noexcept;

} // namespace iblcheck
