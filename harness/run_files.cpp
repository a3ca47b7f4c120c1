#include "run_files.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/core.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "kernel/atomic_file.h"
#include "kernel/errors.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {

const char* const kLock = ".iblcheck.lock";

// Opens and locks `lock` (without waiting); -1 when it does not exist and `create` is false.
// Throws UsageError naming `dir` and the pid written in the lock when another run holds it.
int lock_run(const fs::path& dir, bool create) {
    const fs::path lock = dir / kLock;
    const int fd = ::open(lock.c_str(), O_RDWR | O_CLOEXEC | (create ? O_CREAT : 0), 0644);
    if (fd < 0 && !create && errno == ENOENT) return -1;
    if (fd < 0) throw InputError(lock.string() + ": cannot open: " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        char buf[32] = {};
        const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
        ::close(fd);
        throw UsageError(fmt::format("{}: another iblcheck run{} is writing into this folder; wait for it or use "
                                     "another --out",
                                     dir.string(), n > 0 ? fmt::format(" (pid {})", buf) : ""));
    }
    return fd;
}

// An existing --out may be replaced: with `force`, when it is a run folder; without, only when it
// holds nothing but a lock file. Throws UsageError naming it otherwise.
void check_replaceable(const fs::path& out, bool force) {
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(out, ec);
    if (st.type() == fs::file_type::not_found) return;
    if (st.type() != fs::file_type::directory) throw UsageError("--out " + out.string() + ": exists and is not a folder");
    bool files = false, run = false;
    for (const auto& e : fs::directory_iterator(out, ec)) {
        const std::string name = e.path().filename().string();
        files = files || name != kLock;
        run = run || name == kLock || name == "results.json" || name == "index.html";
    }
    if (files && !force)
        throw UsageError("--out " + out.string() +
                         ": holds the files of an earlier run (or others); pass --force to replace "
                         "it whole, or give another folder");
    if (files && !run)
        throw UsageError("--out " + out.string() + ": not a run folder (no results.json, index.html or " + kLock +
                         "); refusing to replace it, even with --force");
    struct stat a {
    }, b{};
    if (::stat(out.c_str(), &a) == 0 && ::stat(out.parent_path().c_str(), &b) == 0 && a.st_dev != b.st_dev)
        throw UsageError("--out " + out.string() +
                         ": a mount point; a run is written beside its --out and swapped in, "
                         "so give a folder inside it");
}

} // namespace

RunFolder::RunFolder(const fs::path& out, bool force) {
    if (out.empty()) return;
    out_ = fs::absolute(out).lexically_normal();
    if (!out_.has_filename()) out_ = out_.parent_path(); // "report/"
    check_replaceable(out_, force);
    old_lock_fd_ = lock_run(out_, false); // a run of an older iblcheck, or one swapping in
    partial_ = out_.parent_path() / ("." + out_.filename().string() + ".partial");
    std::error_code ec;
    fs::create_directories(partial_, ec);
    if (ec) throw InputError(partial_.string() + ": cannot create the run's folder: " + ec.message());
    lock_fd_ = lock_run(partial_, true);
    const std::string pid = std::to_string(::getpid());
    if (::ftruncate(lock_fd_, 0) == 0 && ::pwrite(lock_fd_, pid.data(), pid.size(), 0) < 0) {}
    for (const auto& e : fs::directory_iterator(partial_, ec)) // a killed run's leftovers
        if (e.path().filename() != kLock) fs::remove_all(e.path(), ec);
}

void RunFolder::commit() {
    if (out_.empty()) return;
    std::error_code ec;
    const bool replace = fs::exists(out_, ec);
    int rc = replace ? ::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, out_.c_str(), RENAME_EXCHANGE)
                     : ::rename(partial_.c_str(), out_.c_str());
    if (rc != 0 && replace && (errno == EINVAL || errno == ENOSYS)) { // a file system without the exchange
        const fs::path old = out_.parent_path() / ("." + out_.filename().string() + ".old");
        fs::remove_all(old, ec);
        rc = ::rename(out_.c_str(), old.c_str()) == 0 ? ::rename(partial_.c_str(), out_.c_str()) : -1;
        if (rc == 0) fs::rename(old, partial_, ec);
    }
    if (rc != 0)
        throw InputError(
            fmt::format("{}: cannot move the run in from {}: {}", out_.string(), partial_.string(), std::strerror(errno)));
    committed_ = true;
    fs::remove_all(partial_, ec); // the earlier run
}

RunFolder::~RunFolder() {
    std::error_code ec;
    if (!committed_ && !partial_.empty()) fs::remove_all(partial_, ec);
    if (lock_fd_ >= 0) ::close(lock_fd_);
    if (old_lock_fd_ >= 0) ::close(old_lock_fd_);
}

void write_json_atomically(const fs::path& file, const nlohmann::json& j) {
    write_file_atomically(file, j.dump(1) + "\n", "results JSON");
}

} // namespace iblcheck
