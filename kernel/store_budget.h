// The stores' size budget (issue 33). Each store entry is named by a hash of every input, so a
// renderer or metric change, a new environment or a bisect step adds entries and never replaces
// old ones: with no bound the stores only grew (5.1 GB of precomputes, 1530 entries, on the
// development machine after two days of work; a ci suite's set is ~130 MB, a nightly's ~1 GB).
//
// The policy is least recently used. An entry's modification time is its last use: a write sets it
// and a read that hits sets it again (store_entry.cpp). After a command that wrote entries (only a
// write makes the stores grow), the oldest entries are removed until the stores fit the budget,
// except those the command itself used: a run whose own entries exceed the budget keeps them, and
// the next command that writes removes them first if it does not use them. Removing an entry is
// never wrong, only slower: its work is done again on the next miss.
//
// The budget is IBLCHECK_CACHE_MAX_MB (MiB, a whole number from 1), default 2048: a nightly's set,
// a ci suite's and room for a dozen older sets (bisect steps). The SPIR-V cache (a few MB) is not
// counted.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace iblcheck {

inline constexpr std::uintmax_t kDefaultStoreBudgetMiB = 2048;

// One store's folder and its entries' suffix: an entry is a regular file named <hex key><suffix>
// (a writer's temporary file, or anything else, is not one and is never removed). An empty `dir`
// is a store turned off.
struct StoreFolder {
    std::filesystem::path dir;
    std::string suffix;
};

struct StoreUsage {
    std::size_t entries = 0;
    std::uintmax_t bytes = 0;
};

struct PruneOutcome {
    StoreUsage before, after;
    std::size_t removed = 0;
    std::uintmax_t removed_bytes = 0;
};

// The budget in bytes: $IBLCHECK_CACHE_MAX_MB MiB, else the default. A value that is not a whole
// number from 1 is a UsageError naming the variable and the value.
std::uintmax_t store_budget_bytes();

// Whether `name` is an entry's file name for `suffix` (<hex key><suffix>).
bool is_store_entry_name(const std::string& name, const std::string& suffix);

// The entries in `folders` and their size.
StoreUsage store_usage(const std::vector<StoreFolder>& folders);

// Removes the least recently used entries of `folders`, oldest first, until they fit `budget`
// bytes; an entry used at or after `keep_since` stays whatever the budget. Errors (an entry another
// process removed first, a read-only folder) are skipped.
PruneOutcome prune_stores(const std::vector<StoreFolder>& folders, std::uintmax_t budget,
                          std::filesystem::file_time_type keep_since);

} // namespace iblcheck
