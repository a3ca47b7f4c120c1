#include "kernel/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <thread>

#include "kernel/errors.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {
std::string cannot_write(const fs::path& file, const std::string& what, const std::string& reason) {
    return file.string() + ": cannot write" + (what.empty() ? "" : " " + what) + ": " + reason;
}

// Renames `tmp` over `file`; on failure removes `tmp` and throws.
void move_into_place(const fs::path& tmp, const fs::path& file, const std::string& what) {
    std::error_code ec;
    fs::rename(tmp, file, ec);
    if (!ec) return;
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw InputError(cannot_write(file, what, ec.message()));
}
} // namespace

fs::path temporary_path(const fs::path& file) {
    fs::path tmp = file;
    tmp += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id()));
    tmp += file.extension(); // the image writers pick the format by it
    return tmp;
}

void write_file_atomically(const fs::path& file, std::string_view bytes, const std::string& what) {
    // A device or a pipe named as the output (/dev/stdout, /dev/full, a FIFO) is written into: a rename
    // would replace the node itself (run as root, `--junit /dev/full` turned /dev/full into a regular
    // file when the JUnit writer became atomic; HostileOutput.AFullDiskAsOutIsExitTwoNamingThePath).
    std::error_code ec;
    if (const fs::file_status st = fs::status(file, ec); !ec && fs::exists(st) && !fs::is_regular_file(st)) {
        errno = 0;
        std::ofstream f(file, std::ios::binary);
        f.write(bytes.data(), std::streamsize(bytes.size()));
        f.close();
        if (!f) throw InputError(cannot_write(file, what, errno ? std::strerror(errno) : "write failed"));
        return;
    }
    const fs::path tmp = temporary_path(file);
    errno = 0; // the reason a failed write gives is the one it sets
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        f.write(bytes.data(), std::streamsize(bytes.size()));
        f.close(); // a full disk shows at the last write, on close
        if (!f) {
            const std::string reason = errno ? std::strerror(errno) : "write failed";
            std::error_code ec;
            fs::remove(tmp, ec);
            throw InputError(cannot_write(file, what, reason));
        }
    }
    move_into_place(tmp, file, what);
}

void write_file_atomically(const fs::path& file, const std::function<void(const fs::path&)>& write, const std::string& what) {
    std::error_code ec;
    if (const fs::file_status st = fs::status(file, ec); !ec && fs::exists(st) && !fs::is_regular_file(st)) {
        write(file); // a device or a FIFO: written into, as above
        return;
    }
    const fs::path tmp = temporary_path(file);
    try {
        write(tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    move_into_place(tmp, file, what);
}

bool try_write_file_atomically(const fs::path& file, std::string_view bytes) noexcept {
    try {
        write_file_atomically(file, bytes);
        return true;
    } catch (...) {
        return false;
    }
}

} // namespace iblcheck
