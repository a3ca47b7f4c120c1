// Issue 14: the holes where a regression passed or got the wrong exit code, one test each. Every
// test here failed on the code before the fix (the note on the issue lists which fix each pins).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "harness/golden_store.h"
#include "harness/runner.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_gate_holes {

namespace {

using namespace iblcheck::testutil;

const char* kMiniSuite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}, "ssim.mean": {"min": 0.999}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.0}}},
  "tests": [{"scene": "furnace", "method": "mobile"}]
})";
const std::string& kMiniTest = kFurnaceTest;

// A private golden folder with the furnace reference and freshly blessed mini baselines.
struct MiniStore : FurnaceStore {
    explicit MiniStore(const std::string& name) : FurnaceStore(name, kMiniSuite) { EXPECT_EQ(bless_all(), kExitPass); }
    RunSummary run(const fs::path& out = {}) const {
        RunOptions o;
        o.suite = suite.string();
        o.goldens = goldens;
        o.quiet = true;
        o.out_dir = out;
        return run_suite(o);
    }
    std::string cli(const std::string& args) const {
        return built("iblcheck") + " " + args + " --suite " + suite.string() + " --goldens " + goldens.string();
    }
};

// A copy of the shaders with `from` replaced by `to` in `file`; returns the env prefix that uses it.
std::string modified_shaders(const fs::path& dir, const std::string& file, const std::string& from, const std::string& to) {
    fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "renderers/shaders", dir / "shaders", fs::copy_options::recursive);
    fs::path f = dir / "shaders" / file;
    std::string text = read_text(f);
    EXPECT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), from.size(), to);
    std::ofstream(f) << text;
    return "IBLCHECK_CACHE_DIR=" + dir.string() + " IBLCHECK_SHADER_DIR=" + (dir / "shaders").string() + " ";
}

} // namespace

TEST(GateHoles, GoldenWithNanPixelsIsAnInputErrorNamingTheFile) {
    // It used to pass: SSIM became NaN and a NaN comparison counted as a pass.
    MiniStore s("nan_golden");
    Golden g = GoldenStore(s.goldens).baselines(kMiniTest)[0];
    g.image.at<cv::Vec3f>(5, 7)[1] = std::numeric_limits<float>::quiet_NaN();
    GoldenStore::write_golden(s.baseline(), g.image, g.provenance);
    RunSummary r = s.run();
    const json& t = r.results["tests"][0];
    EXPECT_EQ(t["verdict"], "error");
    EXPECT_EQ(r.exit_code(), kExitError);
    std::string msg = t["message"];
    EXPECT_NE(msg.find(s.baseline().string() + ": 1 non-finite value(s) (NaN/Inf), first at x=7, y=5"), std::string::npos) << msg;
}

TEST(GateHoles, GoldenWithoutItsSidecarIsAnErrorNamingTheFile) {
    // It used to pass with the reference band silently dropped.
    MiniStore s("no_sidecar");
    fs::remove(fs::path(s.baseline()).replace_extension(".json"));
    RunSummary r = s.run();
    const json& t = r.results["tests"][0];
    EXPECT_EQ(t["verdict"], "error");
    std::string msg = t["message"];
    EXPECT_NE(msg.find(fs::path(s.baseline()).replace_extension(".json").string() + ": golden sidecar missing"),
              std::string::npos)
        << msg;
}

TEST(GateHoles, GoldenOfTheWrongSizeFailsWithBothSizesAndTheReportIsStillWritten) {
    MiniStore s("wrong_size");
    Golden g = GoldenStore(s.goldens).baselines(kMiniTest)[0];
    cv::Mat small;
    cv::Mat(g.image, cv::Rect(0, 0, 64, 32)).copyTo(small);
    GoldenStore::write_golden(s.baseline(), small, g.provenance);
    fs::path out = s.dir / "out";
    RunSummary r = s.run(out);
    const json& t = r.results["tests"][0];
    EXPECT_EQ(t["verdict"], "fail");
    EXPECT_EQ(r.exit_code(), kExitRegression);
    std::string msg = t["message"];
    EXPECT_NE(msg.find("but the baseline golden is 64x32"), std::string::npos) << msg;
    EXPECT_NE(msg.find(fmt::format("size {}x{}", g.image.cols, g.image.rows)), std::string::npos) << msg;
    // The run's own report step accepts its results (it used to reject the size check's string value).
    EXPECT_TRUE(fs::exists(out / "results.json"));
    EXPECT_TRUE(fs::exists(out / "index.html"));
    std::string report_out;
    EXPECT_EQ(run_command(built("iblcheck") + " report " + (out / "results.json").string() + " --out " + (s.dir / "rep").string(),
                          report_out),
              0)
        << report_out;
}

TEST(GateHoles, ShaderThatWritesNanIsARegressionForRunBisectAndRender) {
    // It used to be an "error" (exit 2, bisect 125), so git bisect skipped the guilty commit.
    fs::path dir = temp_dir("nan_shader");
    std::string env = modified_shaders(dir, "shade_spheres.comp", "sum / float(n * n); // alpha = coverage",
                                       "sum / float(n * n) * uintBitsToFloat(0x7fc00000u); // a quiet NaN");
    std::string out;
    const std::string filter = " --filter 'mobile.roughness_sweep.studio.default'";
    EXPECT_EQ(run_command(env + built("iblcheck") + " run --suite ci -q --json " + (dir / "r.json").string() + filter, out), 1)
        << out;
    json r = json::parse(read_text(dir / "r.json"));
    EXPECT_EQ(r["tests"][0]["verdict"], "fail");
    EXPECT_NE(r["tests"][0]["message"].get<std::string>().find("non-finite value(s) (NaN/Inf), first at x=0, y=0"),
              std::string::npos)
        << r["tests"][0]["message"];
    EXPECT_EQ(run_command(env + built("iblcheck") + " bisect" + filter, out), 1) << out;
    EXPECT_NE(out.find("bisect verdict: bad"), std::string::npos) << out;
    EXPECT_EQ(run_command(env + built("iblcheck") + " render --scene sphere --out " + (dir / "nan.exr").string(), out), 1) << out;
    EXPECT_NE(out.find("non-finite"), std::string::npos) << out;
    EXPECT_TRUE(fs::exists(dir / "nan.exr")); // written first, to be inspected
    fs::remove_all(dir);
}

TEST(GateHoles, BlessLeavesUnchangedGoldensUntouchedAndPrintsOnlyAfterWriting) {
    MiniStore s("bless_same");
    const auto t_img = fs::last_write_time(s.baseline());
    const std::string side = read_text(fs::path(s.baseline()).replace_extension(".json"));
    std::string out;
    EXPECT_EQ(run_command(s.cli("bless"), out), 0) << out;
    EXPECT_NE(out.find("unchanged, left as it is"), std::string::npos) << out;
    EXPECT_EQ(fs::last_write_time(s.baseline()), t_img);
    EXPECT_EQ(read_text(fs::path(s.baseline()).replace_extension(".json")), side); // no new date: no git churn

    // A store whose baseline folder cannot be written: an error naming it, and never "blessed".
    fs::path broken = s.dir / "broken";
    fs::create_directories(broken);
    fs::copy(s.goldens / "reference", broken / "reference", fs::copy_options::recursive); // the truth the test asks for
    std::ofstream(broken / "baseline") << "a file where the folder should be";
    EXPECT_EQ(run_command(built("iblcheck") + " bless --suite " + s.suite.string() + " --goldens " + broken.string(), out), 2)
        << out;
    EXPECT_EQ(out.find("\nblessed"), std::string::npos) << out;
    EXPECT_NE(out.rfind("blessed", 0), 0u) << out;
    EXPECT_NE(out.find((broken / "baseline").string()), std::string::npos) << out;
}

TEST(GateHoles, BlessLabelsAreFileNamesOnly) {
    MiniStore s("labels");
    const std::string side = read_text(fs::path(s.baseline()).replace_extension(".json"));
    std::string out;
    EXPECT_EQ(run_command(s.cli("bless --label ''"), out), 2) << out;         // used to overwrite the primary baseline
    EXPECT_EQ(run_command(s.cli("bless --label ../../evil"), out), 2) << out; // used to write outside the store
    EXPECT_NE(out.find("A-Z a-z 0-9 . _ -"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(s.dir / "evil.exr"));
    EXPECT_FALSE(fs::exists(s.goldens / "evil.exr"));
    EXPECT_EQ(read_text(fs::path(s.baseline()).replace_extension(".json")), side);
    // A good label records the platform it was blessed on.
    EXPECT_EQ(run_command(s.cli("bless --label amd-zen4"), out), 0) << out;
    json prov =
        json::parse(read_text(fs::path(GoldenStore(s.goldens).baseline_path(kMiniTest, "amd-zen4")).replace_extension(".json")));
    EXPECT_EQ(prov["label"], "amd-zen4");
    for (const char* k : {"driver", "cpu_features", "cpu_class"}) EXPECT_TRUE(prov.contains(k)) << k;
}

TEST(GateHoles, BlessCommandPrintedForASuiteGivenByPathWorks) {
    MiniStore s("suite_path");
    fs::remove(s.baseline());
    fs::remove(fs::path(s.baseline()).replace_extension(".json"));
    RunSummary r = s.run();
    ASSERT_EQ(r.results["tests"][0]["verdict"], "missing-golden") << r.results["tests"][0]["message"];
    std::string cmd = r.results["tests"][0]["bless_command"];
    EXPECT_NE(cmd.find(s.suite.string()), std::string::npos) << cmd; // the path, not the name "mini"
    std::string out;
    ASSERT_EQ(cmd.rfind("iblcheck ", 0), 0u);
    // The command names the golden store the run used (a run with --goldens prints it), so it runs as printed.
    EXPECT_NE(cmd.find(" --goldens " + s.goldens.string()), std::string::npos) << cmd;
    EXPECT_EQ(run_command("cd / && " + built("iblcheck") + cmd.substr(8), out), 0) << out;
    EXPECT_TRUE(fs::exists(s.baseline()));
}

TEST(GateHoles, SecondRunIntoTheSameOutFolderIsRefused) {
    MiniStore s("out_lock");
    fs::path out = s.dir / "out";
    fs::create_directories(out);
    int fd = ::open((out / ".iblcheck.lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0); // as a running iblcheck holds it
    std::string text;
    EXPECT_EQ(run_command(s.cli("run -q --out " + out.string()), text), 2) << text;
    EXPECT_NE(text.find("another iblcheck run"), std::string::npos) << text;
    ::close(fd);
    EXPECT_EQ(run_command(s.cli("run -q --out " + out.string()), text), 0) << text;
}

TEST(GateHoles, CtestFormNeverPassesWithoutRunning) {
    // The ci suite as GoogleTest cases: names with ':' used to match no filter and pass, shards > 0
    // used to run nothing and pass, and a filter matching nothing passed.
    std::string out;
    const std::string ci = built("tests/test_suite_ci");
    EXPECT_EQ(run_command(ci + " --gtest_filter=ci.no_such_test", out), 1) << out;
    EXPECT_NE(out.find("ran no test"), std::string::npos) << out;
    // A golden root with the truth the tests ask for and no baselines (a wrong root is an input
    // error since issue 30, so it no longer stands for "no baselines").
    const fs::path no_baselines = temp_dir("no_baselines");
    fs::create_directories(no_baselines / "reference");
    for (const char* f : {"furnace__constant-1", "roughness_sweep__studio"})
        for (const char* ext : {".exr", ".json"})
            fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "goldens/reference" / (std::string(f) + ext), no_baselines / "reference");
    const std::string no_goldens = "IBLCHECK_GOLDEN_DIR=" + no_baselines.string() + " ";
    EXPECT_EQ(run_command(no_goldens + ci + " --gtest_filter=ci.mobile.furnace.constant_1.default", out), 1) << out;
    EXPECT_NE(out.find("missing-golden"), std::string::npos) << out;
    EXPECT_NE(out.find("1 FAILED TEST"), std::string::npos) << out;
    // The first ci test belongs to shard 0 of 3: shard 1 reports it skipped, shard 0 runs it.
    const std::string first = " --gtest_filter=ci.mobile.roughness_sweep.studio.default";
    EXPECT_EQ(run_command("GTEST_SHARD_INDEX=1 GTEST_TOTAL_SHARDS=3 " + ci + first, out), 0) << out;
    EXPECT_NE(out.find("[  SKIPPED ] 1 test"), std::string::npos) << out;
    EXPECT_EQ(run_command(no_goldens + "GTEST_SHARD_INDEX=0 GTEST_TOTAL_SHARDS=3 " + ci + first, out), 1) << out;
    fs::remove_all(no_baselines);
}

TEST(GateHoles, TwiceAsMuchShadingWorkFailsOnCostAndTheFigureIsDeterministic) {
    // A runaway shader passed: a loop made the frame 176x slower and the pixels stayed within
    // tolerance. Now each baseline records the executed SPIR-V instructions per pixel and the test
    // fails past +25 %. Here every ray is shaded twice (the image is bit-identical, so only the
    // cost can catch it).
    fs::path dir = temp_dir("twice");
    std::string env =
        modified_shaders(dir, "shade_spheres.comp", "sum += shade_ray(vec2(px) + (vec2(i, j) + 0.5) / float(n));",
                         "{ vec2 p = vec2(px) + (vec2(i, j) + 0.5) / float(n); sum += 0.5 * (shade_ray(p) + shade_ray(p)); }");
    std::string out;
    const std::string filter = " --filter 'mobile.roughness_sweep.*.default'";
    EXPECT_EQ(run_command(env + built("iblcheck") + " run --suite ci -q --json " + (dir / "r.json").string() + filter, out), 1)
        << out;
    json r = json::parse(read_text(dir / "r.json"));
    ASSERT_EQ(r["tests"].size(), 2u);
    for (const json& t : r["tests"]) {
        EXPECT_EQ(t["verdict"], "fail") << t["name"];
        std::string msg = t["message"];
        EXPECT_NE(msg.find("cost.spirv_instructions_per_pixel"), std::string::npos) << msg;
        EXPECT_NE(msg.find("(approved "), std::string::npos) << msg;
        EXPECT_EQ(msg.find("baseline:"), std::string::npos) << "the pixels did not change: " << msg;
    }
    // Unchanged shaders: the same figure on every run (it counts SPIR-V, not time).
    json a, b;
    ASSERT_EQ(run_command(built("iblcheck") + " run --suite ci -q --json " + (dir / "a.json").string() + filter, out), 0) << out;
    ASSERT_EQ(run_command(built("iblcheck") + " run --suite ci -q --json " + (dir / "b.json").string() + filter, out), 0) << out;
    a = json::parse(read_text(dir / "a.json"));
    b = json::parse(read_text(dir / "b.json"));
    for (size_t i = 0; i < 2; ++i) EXPECT_EQ(a["tests"][i]["cost"], b["tests"][i]["cost"]);
    fs::remove_all(dir);
}
} // namespace test_gate_holes
