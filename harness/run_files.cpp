#include "run_files.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "harness/common/errors.h"

namespace fs = std::filesystem;

namespace iblcheck {

OutDirLock::OutDirLock(const fs::path& dir) {
    if (dir.empty()) return;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot create the output folder: " + ec.message());
    fs::path lock = dir / ".iblcheck.lock";
    fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError(lock.string() + ": cannot open: " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        char buf[32] = {};
        ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
        ::close(fd_);
        throw UsageError(fmt::format("{}: another iblcheck run{} is writing into this folder; wait for it or use "
                                     "another --out",
                                     dir.string(), n > 0 ? fmt::format(" (pid {})", buf) : ""));
    }
    std::string pid = std::to_string(::getpid());
    if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {}
}

OutDirLock::~OutDirLock() {
    if (fd_ >= 0) ::close(fd_);
}

void write_json_atomically(const fs::path& file, const nlohmann::json& j) {
    fs::path tmp = file;
    tmp += ".tmp" + std::to_string(::getpid());
    {
        std::ofstream f(tmp);
        f << j.dump(1) << "\n";
        if (!f) throw InputError(file.string() + ": cannot write results JSON");
    }
    fs::rename(tmp, file);
}

} // namespace iblcheck
