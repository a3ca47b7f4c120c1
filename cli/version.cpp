#include "cli/version.h"

#include <filesystem>
#include <fstream>

namespace iblcheck::cli {

namespace {
// The commit the build was made from: build/iblcheck_commit.txt beside the binary, written at every
// build (cmake/git_version.cmake); "unknown" without it.
std::string build_commit() {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    std::ifstream f(self.parent_path() / "iblcheck_commit.txt");
    std::string commit;
    if (ec || !std::getline(f, commit) || commit.empty()) return "unknown";
    return commit;
}
} // namespace

std::string version_string() {
    return std::string("iblcheck ") + IBLCHECK_VERSION + " (commit " + build_commit() + ", " + IBLCHECK_COMPILER + ", " +
           IBLCHECK_BUILD_TYPE + ")";
}

} // namespace iblcheck::cli
