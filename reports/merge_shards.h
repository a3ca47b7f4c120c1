// One report from a suite sharded over machines (`iblcheck run --shard i/n` on each, then
// `iblcheck report a/results.json b/results.json ... --out DIR --junit FILE`). The shards must be
// one run split: the same suite, commit and dirty state, the same shard count, each index exactly once
// and no test twice; anything else is refused (InputError naming the files and the field), since a
// merged report of two commits would judge neither.
#pragma once
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::report {

// A shard's results with the file they came from (its folder holds the images they name).
struct Shard {
    std::filesystem::path file;
    nlohmann::json results;
};

// The merged results (schema iblcheck-results/1): the tests in the suite's order (`run --shard` deals
// them round robin: shard k holds positions k, k + n, ...), counts recomputed, total_s the slowest
// shard's, started the earliest, "shard" "0/1" (the whole suite), the command without its --shard, and
// "shards": [{"file", "shard", "started", "total_s", "tests"}] saying where each part came from.
nlohmann::json merge_shards(const std::vector<Shard>& shards);

} // namespace iblcheck::report
