#include "kernel/store_entry.h"

#include <atomic>
#include <cstdlib>
#include <fstream>

#include "kernel/atomic_file.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {
std::atomic<bool> g_written{false};

// An entry's modification time is its last use (store_budget.h): the least recently used go first.
// Set from the fine clock (a write's own time comes from the kernel's coarse one); a failure (a
// read-only store) only makes the entry look older.
void mark_used(const fs::path& file) {
    std::error_code ec;
    fs::last_write_time(file, fs::file_time_type::clock::now(), ec);
}
} // namespace

bool store_entries_written() { return g_written.load(std::memory_order_relaxed); }

fs::path store_dir(const char* env_var, const fs::path& default_dir) {
    if (const char* dir = std::getenv(env_var); dir && *dir) return std::string(dir) == "0" ? fs::path() : fs::path(dir);
    return default_dir;
}

// Read in one call of the file's size: a 50 MB precompute entry took 740 ms through an
// istreambuf_iterator (a character at a time, then the head erased: the whole entry moved), 68 ms so.
std::optional<std::string> read_store_entry(const fs::path& file, std::string_view head) {
    std::ifstream f(file, std::ios::binary | std::ios::ate);
    if (!f) return std::nullopt;
    const std::streamoff size = f.tellg();
    if (size < std::streamoff(head.size())) return std::nullopt;
    std::string start(head.size(), '\0');
    f.seekg(0);
    if (!f.read(start.data(), std::streamsize(start.size())) || start != head) return std::nullopt;
    std::string bytes(size_t(size) - head.size(), '\0');
    if (!f.read(bytes.data(), std::streamsize(bytes.size()))) return std::nullopt;
    mark_used(file);
    return bytes;
}

void write_store_entry(const fs::path& file, std::string_view bytes) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (!try_write_file_atomically(file, bytes)) return; // no error: the next run does the work again
    g_written.store(true, std::memory_order_relaxed);
    mark_used(file);
}

} // namespace iblcheck
