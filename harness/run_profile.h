// `iblcheck run --profile` (issue 33): where a run's time went, per stage and per test. Each test's
// results object carries "profile" (seconds per stage, kernel/profile.h); this sums them over the
// run, adds the run's own stages (the report, the files), and prints the table.
#pragma once
#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace iblcheck {

// Stage → seconds over every test of `results` ("tests"[i]["profile"]).
std::map<std::string, double> sum_test_profiles(const nlohmann::json& results);

// The table: each stage's seconds (the tests' summed over the workers, then the run's own), its
// share of the tests' time, then the `slowest` tests with their three largest stages. `wall_s`: the
// run's wall time; `jobs`: its workers (the tests' seconds / wall is how busy they kept the cores).
void print_profile(const nlohmann::json& results, const std::map<std::string, double>& run_stages, double wall_s, int jobs,
                   size_t slowest = 8);

} // namespace iblcheck
