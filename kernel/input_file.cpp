#include "kernel/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "kernel/errors.h"

namespace iblcheck {

namespace {
// What a non-regular file is, in the words of the message.
const char* kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a plain file";
}
} // namespace

void require_regular_file(const std::string& path) {
    struct stat st {};
    // stat(), not open(): opening a FIFO for reading blocks until a writer appears.
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw InputError(fmt::format("{}: file not found", path));
        throw InputError(fmt::format("{}: cannot read ({})", path, std::strerror(errno)));
    }
    if (!S_ISREG(st.st_mode)) throw InputError(fmt::format("{}: is {}, not a regular file", path, kind_of(st.st_mode)));
}

std::ifstream open_input_file(const std::string& path) {
    require_regular_file(path);
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(fmt::format("{}: cannot open ({})", path, std::strerror(errno)));
    return f;
}

} // namespace iblcheck
