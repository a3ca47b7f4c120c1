#include "kernel/store_entry.h"

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "kernel/atomic_file.h"

namespace fs = std::filesystem;

namespace iblcheck {

fs::path store_dir(const char* env_var, const fs::path& default_dir) {
    if (const char* dir = std::getenv(env_var); dir && *dir) return std::string(dir) == "0" ? fs::path() : fs::path(dir);
    return default_dir;
}

std::optional<std::string> read_store_entry(const fs::path& file, std::string_view head) {
    std::ifstream f(file, std::ios::binary);
    if (!f) return std::nullopt;
    std::string bytes((std::istreambuf_iterator<char>(f)), {});
    if (bytes.size() < head.size() || bytes.compare(0, head.size(), head) != 0) return std::nullopt;
    bytes.erase(0, head.size());
    return bytes;
}

void write_store_entry(const fs::path& file, std::string_view bytes) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    try_write_file_atomically(file, bytes); // a failure is no error: the next run does the work again
}

} // namespace iblcheck
