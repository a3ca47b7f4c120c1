// One test of a suite: render, compare, decide (runner.h runs a suite of them on worker threads).
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

#include "golden_store.h"
#include "results/results.h"
#include "suite.h"
#include "worker.h"

namespace iblcheck {

// The test's results (results/results.h, results/RESULTS_FORMAT.md): its render, every comparison, temporal
// and stability checks, the verdict and why. Images go under out_dir/images/<test>/ unless out_dir
// is empty. Never throws: every outcome becomes a verdict; a shader that does not compile also sets
// `shader_error` (bisect: 125). `timing_repeats` > 1 renders again for the median frame time.
TestResult run_test(const TestCase& tc, Worker& w, const GoldenStore& store, const std::filesystem::path& out_dir,
                    int flip_threads, int timing_repeats, bool& shader_error);

} // namespace iblcheck
