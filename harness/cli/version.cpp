#include "harness/cli/version.h"

#include "iblcheck_git_version.h" // generated at build time by cmake/git_version.cmake

namespace iblcheck::cli {

std::string version_string() {
    return std::string("iblcheck ") + IBLCHECK_VERSION + " (commit " + IBLCHECK_GIT_COMMIT + ", " + IBLCHECK_COMPILER + ", " +
           IBLCHECK_BUILD_TYPE + ")";
}

} // namespace iblcheck::cli
