// Runs a suite: render → metrics → verdict → results JSON (+ JUnit, images). The runner knows no
// Vulkan (it calls Renderer) and writes no goldens except through bless().
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "golden_store.h"
#include "suite.h"

namespace iblcheck {

struct RunOptions {
    std::string suite = "ci";
    std::string filter;                 // glob on test names
    int shard_index = 0, shard_count = 1;
    int jobs = 0;                       // 0: the suite's default
    std::filesystem::path out_dir;      // results.json, images/, index.html; empty: no files
    std::filesystem::path junit;        // JUnit XML
    std::filesystem::path json;         // results JSON copy
    std::filesystem::path history;      // append one line per run
    std::filesystem::path goldens;      // golden root override
    std::string device;                 // Vulkan device override
    std::string command_line;           // for the report
    bool quiet = false;
    bool report = true;                 // write index.html when out_dir is set
    bool stability = false;             // measure determinism, noise floors and margins for every test
};

struct RunSummary {
    nlohmann::json results;
    int pass = 0, fail = 0, improved = 0, missing = 0, error = 0;
    bool shader_compile_error = false;  // some render failed to compile its shaders (bisect: 125)
    int exit_code() const;
};

RunSummary run_suite(const RunOptions& options);

struct BlessOptions {
    std::string suite = "ci";
    std::string filter;
    std::string label;                  // "" primary baseline, else an alternate baseline@label
    std::filesystem::path goldens;
    std::string device;
    bool dry_run = false;
};
// Re-renders and writes baselines; returns the exit code (2 if any render failed: nothing is
// written for a failed render).
int bless(const BlessOptions& options);

// The bless command that approves a test (shown on failure).
std::string bless_command(const TestCase& t);

// Writes JUnit XML for results (one testcase per test).
void write_junit(const nlohmann::json& results, const std::filesystem::path& file);

} // namespace iblcheck
