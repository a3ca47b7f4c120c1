// Failures that share a cause (issue 32): one shader constant can fail 45 tests the same way. The
// report shows one representative card per group with the others folded, and the run's terminal
// prints one short approve command per group instead of every name spelt out.
//
// A group is the tests that did not pass with the same verdict, the same comparisons failing (the
// baseline, the truth band; the metrics that failed are counted, not matched: one constant fails
// ssim.mean on some of its tests only), and the same shader change since their baselines (the shader files
// whose content differs, by file, where the baselines recorded them; else the shader tree hash).
// Pure: tests/test_failure_groups.cpp.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::report {

struct FailureGroup {
    std::string verdict;               // fail, error, missing-golden, improved
    std::string checks;                // the comparisons that failed, "baseline"; or the error's message
    std::vector<std::string> metrics;  // "baseline flip.mean (45)", "baseline ssim.mean (30)": the checks that failed
    std::string shader_change;         // "mip_mapping.glsl changed", "shader tree c463237a -> 9d1f0e2b", ""
    std::vector<size_t> members;       // indices into the tests given, the representative first
    std::vector<std::string> spheres;  // "metal r=0.3 (12)", most common first: where the worst blocks lie
    std::vector<std::string> variants; // "dominant_dir (8)": the option keys the members change
    std::string filter;                // --filter that selects exactly the members among the run's tests
};

// Groups the tests whose verdict is not pass, largest group first. `tests` are results.json test
// objects; `run_is_whole_suite`: the run had no --filter and no --shard, so a glob that matches no
// other test of the run matches no other test of the suite (else the filter spells out the names).
std::vector<FailureGroup> group_failures(const std::vector<const nlohmann::json*>& tests, bool run_is_whole_suite);

// Whether `results` (its "command" and "shard") ran the whole suite.
bool ran_whole_suite(const nlohmann::json& results);

// A short `--filter` (kernel/name_filter.h) found greedily that selects every name of
// `members` and no other name of `all` (`all` holds the members too): the shorter of globs that
// match only members, and one glob over every member with `!GLOB`s for the others it catches.
// Globs replace name parts (method.scene.env.variant) with '*' or keep one option ('*KEY=VALUE*',
// '*KEY=*'); a name no glob covers is spelt out, escaped.
std::string covering_filter(const std::vector<std::string>& members, const std::vector<std::string>& all);

// "approve 45 failures (after looking at them): iblcheck bless --suite 'ci' --filter '*.default'":
// the program, the suite, --shader and --goldens as the members' own bless commands name them.
std::string group_bless_line(const std::vector<const nlohmann::json*>& tests, const FailureGroup& g, const std::string& suite_arg,
                             const std::string& shader_arg);

// One line saying what the group shares: "45 fail · baseline flip.mean · shader tree a -> b · worst
// on metal r=0.3 (12), metal r=0.4 (9), 3 more".
std::string group_summary(const FailureGroup& g);

} // namespace iblcheck::report
