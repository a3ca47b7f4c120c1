#include "cli/store_folders.h"

#include "harness/metrics_store.h"
#include "harness/sequence_store.h"
#include "renderers/mobile/cost_store.h"
#include "renderers/mobile/precompute_store.h"

namespace iblcheck::cli {

// The suffixes are the stores' own entry names (precompute_store.cpp, cost_store.cpp, metrics_store.cpp,
// sequence_store.cpp).
std::vector<StoreFolder> store_folders() {
    return {{precompute_store_dir(), ".ibl"},
            {cost_store_dir(), ".cost"},
            {metrics_store_dir(), ".metrics"},
            {sequence_store_dir(), ".frames"}};
}

} // namespace iblcheck::cli
