// The on-disk stores the size budget covers (kernel/store_budget.h): precomputes, instruction
// counts and metrics, each where its IBLCHECK_*_CACHE variable or the cache folder puts it.
#pragma once
#include <vector>

#include "kernel/store_budget.h"

namespace iblcheck::cli {

std::vector<StoreFolder> store_folders();

} // namespace iblcheck::cli
