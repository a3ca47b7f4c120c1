// Issue 33: the ci suite's time. `run --profile` says where it goes (per stage, per test), and the
// work shared between tests stays correct. No test here measures a time: each checks what the
// profile names and that its figures add up, or that a cache misses when an input changes
// (scripts/bench_speed.sh prints the timings).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "harness/common/profile.h"
#include "harness/runner.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

namespace {

// Work the compiler cannot drop, so a stage has a duration above zero.
double spin(int n) {
    volatile double x = 0;
    for (int i = 0; i < n; ++i) x = x + 1e-9 * i;
    return x;
}

const char* kSuite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}, "ssim.mean": {"min": 0.999}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.0}}},
  "tests": [{"scene": "furnace", "method": "mobile", "variants": [{}, {"storage": "astc_hdr"}]}]
})";

} // namespace

// Nested stages: the outer stage's clock stops while the inner one runs, so neither counts the
// other's time; off, nothing is recorded.
TEST(Profile, StagesNestExclusivelyAndRecordNothingWhenOff) {
    profile::enable(false);
    profile::take();
    {
        ProfileStage outer("outer");
        spin(100000);
    }
    EXPECT_TRUE(profile::take().empty());

    profile::enable(true);
    profile::take();
    const auto t0 = std::chrono::steady_clock::now();
    {
        ProfileStage outer("outer");
        spin(200000);
        {
            ProfileStage inner("inner");
            spin(200000);
        }
        spin(200000);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto stages = profile::take();
    profile::enable(false);
    ASSERT_EQ(stages.size(), 2u);
    EXPECT_GT(stages.at("outer"), 0.0);
    EXPECT_GT(stages.at("inner"), 0.0);
    // Exclusive: together they are the block's wall time, never more (nested time counted twice was).
    EXPECT_LE(stages.at("outer") + stages.at("inner"), wall);
    EXPECT_TRUE(profile::take().empty()); // take() cleared them
}

// `run --profile` prints the stages of the issue and each test's results carry them; the stages
// of a test add up to (at most) its wall time. Without it the results have no "profile".
TEST(Profile, RunPrintsStagesAndEachTestRecordsThem) {
    FurnaceStore store("profile_run", kSuite);
    ASSERT_EQ(store.bless_all(), kExitPass);
    const fs::path out = store.dir / "out";
    std::string text;
    const std::string cmd = std::string(IBLCHECK_BINARY_DIR) + "/iblcheck run --suite " + store.suite.string() + " --goldens " +
                            store.goldens.string() + " -q --jobs 1 --profile --out " + out.string();
    ASSERT_EQ(run_command(cmd, text), 0) << text;
    for (const char* stage : {"profile:", "precompute", "astc_encode", "spirv_compile_or_cache", "pipeline_create", "shading",
                              "counting_twin", "metrics", "files", "results_and_report", "slowest tests"})
        EXPECT_NE(text.find(stage), std::string::npos) << stage << " not in:\n" << text;
    const json results = json::parse(read_text(out / "results.json"));
    ASSERT_EQ(results["tests"].size(), 2u);
    for (const json& t : results["tests"]) {
        ASSERT_TRUE(t.contains("profile")) << t["name"];
        double sum = 0;
        for (const auto& [stage, s] : t["profile"].items()) sum += s.get<double>();
        EXPECT_GT(t["profile"].value("shading", 0.0), 0.0) << t["name"];
        EXPECT_GT(t["profile"].value("metrics", 0.0), 0.0) << t["name"];
        EXPECT_LE(sum, t["wall_s"].get<double>() + 1e-3) << t["name"]; // exclusive stages: no time counted twice
    }
    EXPECT_GT(results["tests"][1]["profile"].value("astc_encode", 0.0), 0.0); // the ASTC variant's encode is its own stage

    RunOptions o;
    o.suite = store.suite.string();
    o.goldens = store.goldens;
    o.quiet = true;
    const RunSummary plain = run_suite(o);
    EXPECT_FALSE(plain.results["tests"][0].contains("profile"));
}
