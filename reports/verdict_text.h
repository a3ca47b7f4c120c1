// What a failure says, in words, from the results JSON of one test: `iblcheck run` prints these
// lines under the test and the report shows them on its card (pure: tests/test_report.cpp).
// A failure says what failed, where and by how much, what it did to the accuracy against the
// truth, and how to approve it, so nobody has to open the report to decide:
//
//   [ 3/31] fail  mobile.roughness_sweep.sky_sun.dominant_dir=lagarde  vs truth 0.2990  (1.9 s)
//             baseline: flip.mean 0.0123 > 0.001 (+0.0113)
//             worst 16x16 block at (96,16) on metal r=0.3, mean FLIP 0.42
//             accuracy vs truth: 0.2844 -> 0.2990 (+5.1 %), band [0.2276, 0.3146]
//             approve: iblcheck bless --suite 'ci' --filter 'mobile.roughness_sweep.sky_sun.dominant_dir=lagarde'
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::report {

// The lines under a test that did not pass (none for a pass): each failing or improved check,
// the worst block of a failing image comparison with the sphere it lies on, the accuracy against
// the truth approved -> now, the bless command (fail, missing-golden, improved) or the message.
std::vector<std::string> verdict_details(const nlohmann::json& test);

// One line that approves every failure (fail and missing-golden) of the run, or "" when there is
// none: `iblcheck bless --suite 'S' --filter 'a|b|c'` (--filter takes globs separated by '|').
// `shader_arg`: the run's `--shader FILE`, repeated (empty: none). `whole_suite`: `tests` are every
// test of the suite (ran_whole_suite, failure_groups.h), so the filter may be globs that match the
// failures and no other test (covering_filter) instead of every name.
std::string rebless_all_line(const nlohmann::json& tests, const std::string& suite_arg, const std::string& shader_arg = "",
                             bool whole_suite = false);

} // namespace iblcheck::report

namespace iblcheck {
using report::rebless_all_line;
using report::verdict_details;
} // namespace iblcheck
