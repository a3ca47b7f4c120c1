// `iblcheck --version`: what was built, from which commit, with which compiler.
#pragma once
#include <string>

namespace iblcheck::cli {

// "iblcheck 0.1 (commit 0123456789ab[-dirty], GCC 12.2.0, RelWithDebInfo)"; the commit is the
// checkout's HEAD when the binary was built ("unknown" outside a git checkout).
std::string version_string();

} // namespace iblcheck::cli
