// Runs a suite: render → metrics (metrics/image_compare.h) → verdict (verdict.h) → results JSON (+ JUnit,
// report, images). The runner knows no Vulkan (it calls Renderer) and writes no goldens (bless.h
// does). Here: the worker threads and the results document. One test's recipe is one_test.h; its
// comparisons with the goldens golden_comparisons.h; its image files artefacts.h; stability and
// temporal checks stability.h and temporal_check.h; the output folder's lock and the atomic JSON
// run_files.h; what a run prints run_console.h.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "batch_queue.h"
#include "bless.h"
#include "golden_store.h"
#include "results/junit.h"
#include "suite.h"
#include "verdict.h"

namespace iblcheck {

struct RunOptions {
    std::string suite = "ci";
    std::string shader; // --shader: a team's shading file for every mobile test (suite.h)
    std::string filter; // glob on test names
    int shard_index = 0, shard_count = 1;
    int jobs = 0;                  // 0: the suite's default
    std::filesystem::path out_dir; // results.json, images/, index.html (run_files.h: RunFolder); empty: no files
    std::filesystem::path junit;   // JUnit XML
    std::filesystem::path json;    // results JSON copy
    std::filesystem::path history; // append one line per run
    std::filesystem::path goldens; // golden root override
    std::string device;            // Vulkan device override
    std::string command_line;      // for the report
    bool quiet = false;
    bool force = false;           // replace an earlier run's --out, overwrite --json and --junit files
    bool report = true;           // write index.html when out_dir is set
    bool stability = false;       // measure determinism, noise floors and margins for every test
    bool stored_sequences = true; // temporal frames after the first may come from the store (sequence_store.h)
    // --findings: `iblcheck explain/explore --json` files for the report's findings (nightly_findings.h)
    std::vector<nlohmann::json> findings;
    bool profile = false; // print where the time went (run_profile.h); each test's results gain "profile"
};

// The run's results (results/results.h, as JSON) and how many tests got each verdict.
struct RunSummary : VerdictCounts {
    nlohmann::json results;
    bool shader_compile_error = false; // some render failed to compile its shaders (bisect: 125)
    int exit_code() const;             // verdict.h: run_exit_code
};

RunSummary run_suite(const RunOptions& options);

// `o` with --history set to the suite's history file beside --out (Suite::history) when the run
// names no --history and has an --out; otherwise `o` unchanged.
RunOptions with_suite_history(RunOptions o, const Suite& suite);
// `tests` (indices) in batches that share a precompute (renderer.h: precompute_share_key), in suite
// order, grouped by the radiance chain they derive from (radiance_chain_share_key), chains with the
// most tests first; the runner's workers take them from a BatchQueue (batch_queue.h), each keeping to
// its chain, so a session computes each chain once and each precompute once. Handed out a test at a
// time, the two workers each computed most of them (the 71 ci tests: ~47 precomputes where 30 differ).
// A test whose options are bad gets a chain of its own (it fails when it runs), and so does each
// CPU-truth test (nothing to share).
std::vector<ChainBatches> precompute_batches(const std::vector<TestCase>& tests);

} // namespace iblcheck
