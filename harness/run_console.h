// What a run prints: one line per test as it finishes (with its failing checks under it), and the
// summary every run prints, -q or not.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "runner.h"

namespace iblcheck {

// "[ 3/61] pass            mobile.sphere.studio.default  vs truth 0.0123  (0.4 s)" and the
// details of a test that did not pass. `interactive`: stdout is a terminal.
void print_test_line(const nlohmann::json& r, int n, size_t total, bool interactive);

// The fp16 path mediump tests took, the counts, and the command that approves every failure.
void print_run_summary(const nlohmann::json& R, const RunSummary& s, size_t n_tests, const RunOptions& o,
                       const std::string& suite_arg, const std::string& shader_arg = "");

} // namespace iblcheck
