// What a run prints: one line per test as it finishes (with its failing checks under it), and the
// summary every run prints, -q or not. A change that fails 45 tests stays readable (issue 32): the
// first failures print their details, the next ones their line only, the rest only the progress;
// the summary then names each group of failures that share a cause (failure_groups.h) with its one
// short approve command. Everything is in the report and results.json.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "runner.h"

namespace iblcheck {

// How much of the failures the per-test lines have said so far (one per run, under the print lock).
struct ConsoleBudget {
    static constexpr int kDetailed = 3; // failures printed with their details
    static constexpr int kListed = 10;  // failures printed with their line
    int not_passed = 0;
};

// "[ 3/61] pass            mobile.sphere.studio.default  vs truth 0.0123  (0.4 s)" and the
// details of a test that did not pass. `interactive`: stdout is a terminal, where a pass is a
// progress line the next line overwrites.
void print_test_line(const nlohmann::json& r, int n, size_t total, bool interactive, ConsoleBudget& budget);

// The fp16 path mediump tests took, the counts, the groups of failures with an approve command
// each, and the command that approves every failure.
void print_run_summary(const nlohmann::json& R, const RunSummary& s, size_t n_tests, const RunOptions& o,
                       const std::string& suite_arg, const std::string& shader_arg = "");

} // namespace iblcheck
