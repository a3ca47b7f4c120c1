// `iblcheck truth` through the built binary: the Monte Carlo golden (--integrator monte_carlo) with its
// noise-floor sidecar, --compare, and nothing overwritten without --force (what
// scripts/regenerate_reference_goldens.sh relies on). The quadrature truth's pixels are tested in
// renderers/reference/*_test.cpp; this is the command line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_truth_command {

namespace {

const std::string kCli = testutil::built("iblcheck");

nlohmann::json read_json(const fs::path& p) {
    std::ifstream f(p);
    return nlohmann::json::parse(f);
}

class TruthCommand : public ::testing::Test {
  protected:
    void SetUp() override { dir_ = testutil::temp_dir("truth_command"); }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

// A 4-spp Monte Carlo golden of a sphere in a white furnace: the sidecar has the noise floor between
// seeds K and K+1 with its criterion, the seeds, spp and seed in the options, and the recorded command.
TEST_F(TruthCommand, MonteCarloGoldenRecordsItsNoiseFloor) {
    std::string out;
    const std::string args =
        " truth --integrator monte_carlo --scene sphere --env constant:1 --spp 4 --seed 2 --out " + path("mc.exr");
    const int rc = testutil::run_command(kCli + args, out);
    ASSERT_TRUE(rc == 0 || rc == 1) << "0: criterion met, 1: not met; got " << rc << "\n" << out;
    ASSERT_TRUE(fs::exists(path("mc.exr"))) << out;
    const nlohmann::json m = read_json(path("mc.json"));
    EXPECT_EQ(m["seeds"], nlohmann::json({2, 3}));
    EXPECT_EQ(m["noise_floor"]["seeds"], nlohmann::json({2, 3}));
    EXPECT_EQ(m["spp"], 4);
    EXPECT_EQ(m["options"], "seed=2,spp=4");
    EXPECT_EQ(m["image"], "mc.exr");
    EXPECT_EQ(m["env"]["spec"], "constant:1");
    for (const char* k : {"relative_rmse", "mean_flip", "mean_value", "covered_pixels", "criterion", "definition"})
        EXPECT_TRUE(m["noise_floor"].contains(k)) << k;
    EXPECT_EQ(m["noise_floor"]["criterion"]["met"].get<bool>(), rc == 0);
    EXPECT_EQ(m["provenance"]["spp"], 4);
    EXPECT_EQ(m["command"], "iblcheck truth --scene sphere --env constant:1 --integrator monte_carlo --spp 4 --seed 2");
}

// An existing golden is kept without --force; with --force it is rewritten, and --compare against a copy
// of the same pixels prints a zero difference. --command replaces the recorded command.
TEST_F(TruthCommand, OverwritesOnlyWithForceAndCompares) {
    std::string out;
    const std::string base =
        kCli + " truth --integrator monte_carlo --scene sphere --env constant:1 --spp 1 --out " + path("g.exr");
    int rc = testutil::run_command(base, out);
    ASSERT_TRUE(rc == 0 || rc == 1) << out;
    fs::copy_file(path("g.exr"), path("old.exr"));
    const auto written = fs::last_write_time(path("g.json"));
    rc = testutil::run_command(base, out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("pass --force to overwrite"), std::string::npos) << out;
    EXPECT_EQ(fs::last_write_time(path("g.json")), written);
    rc = testutil::run_command(base + " --force --command regen.sh --compare " + path("old.exr"), out);
    ASSERT_TRUE(rc == 0 || rc == 1) << out;
    EXPECT_NE(out.find("mean FLIP 0.00000, relative RMSE 0.0000 %"), std::string::npos) << out;
    EXPECT_EQ(read_json(path("g.json"))["command"], "regen.sh");
}

TEST_F(TruthCommand, MonteCarloOptionsNeedTheMonteCarloIntegrator) {
    std::string out;
    for (const std::string bad : {" --spp 4", " --seed 1", " --integrator monte_carlo --tiles 48",
                                  " --integrator monte_carlo --frames 2", " --integrator other"}) {
        const int rc = testutil::run_command(kCli + " truth --scene sphere --env constant:1 --out " + path("x.exr") + bad, out);
        EXPECT_EQ(rc, 2) << bad << "\n" << out;
        EXPECT_FALSE(fs::exists(path("x.exr"))) << bad;
    }
}

// A count that is not positive is a usage error, not a silent plain golden (--frames 0 used to write the
// single-image golden as if --frames had not been given).
TEST_F(TruthCommand, FramesAndSppMustBePositive) {
    std::string out;
    for (const std::string bad : {" --frames 0", " --frames -2", " --integrator monte_carlo --spp 0"}) {
        const int rc = testutil::run_command(kCli + " truth --scene sphere --env constant:1 --out " + path("x.exr") + bad, out);
        EXPECT_EQ(rc, 2) << bad << "\n" << out;
        EXPECT_FALSE(fs::exists(path("x.exr"))) << bad;
    }
}

// --print-name answers the golden's name, the key a suite test reads, and renders and writes nothing: the
// regeneration script asks it instead of spelling the rule again (its bash copy named a truth rendered
// with --set threads=2 "sphere__studio__threads=2", a golden no test reads).
TEST_F(TruthCommand, PrintNameIsTheGoldenStoresKeyAndWritesNothing) {
    std::string out;
    const std::string goldens = " --goldens " + path("goldens");
    int rc = testutil::run_command(kCli +
                                       " truth --print-name --scene sphere --env studio --set threads=2 --set roughness=0.5 "
                                       "--set truth_tolerance=0.01 --size 32x32" +
                                       goldens,
                                   out);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_EQ(out, "sphere__studio__roughness=0.5__32x32\n");
    rc = testutil::run_command(kCli + " truth --print-name --frames 16 --scene sphere_field --env sky_sun" + goldens, out);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_EQ(out, "sphere_field__sky_sun__frames=16\n");
    rc = testutil::run_command(kCli + " truth --print-name --scene roughness_sweep --env blender:sunrise" + goldens, out);
    EXPECT_EQ(out, "roughness_sweep__blender-sunrise\n");
    EXPECT_TRUE(fs::is_empty(dir_)) << "nothing rendered or written";
}

} // namespace
} // namespace test_truth_command
