// A team's own HDRI, end to end through the built binary (issue 29): a suite test with an environment
// file in a temporary folder -> the truth command the run prints -> the bless command it prints -> a
// passing run with a "vs truth" comparison; then a deleted truth and an edited HDRI are errors (exit 2)
// naming the file. The printed commands are run exactly as printed, from the folder they were printed
// in: their first word is the binary that printed them (it was "iblcheck", not found after
// scripts/run.sh). A 32x32 sphere under a 64x32 HDRI keeps it to a few seconds.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "image_io/image_io.h"
#include "kernel/shell_quote.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_own_environment {

namespace {

const std::string kCli = testutil::built("iblcheck");

// A small 2:1 panorama: a sky gradient and one bright patch (so the sphere's shading varies).
void write_hdri(const fs::path& file, float gain) {
    cv::Mat m(32, 64, CV_32FC3);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const float sky = gain * (1.0f - float(y) / m.rows);
            const bool sun = x >= 28 && x < 32 && y >= 8 && y < 11;
            m.at<cv::Vec3f>(y, x) = sun ? cv::Vec3f(40, 38, 30) * gain : cv::Vec3f(0.3f * sky, 0.5f * sky, 0.9f * sky);
        }
    write_exr(file.string(), m);
}

// The text after `marker` (the first after `after`) up to `end` (or the line's end) in `out`.
std::string between(const std::string& out, const std::string& after, const std::string& marker, const std::string& end) {
    const size_t a = out.find(marker, out.find(after));
    if (a == std::string::npos) return "";
    const size_t b = out.find(end, a + marker.size());
    const size_t eol = out.find('\n', a);
    return out.substr(a + marker.size(), std::min(b, eol) - a - marker.size());
}

// The first word of a printed command names an executable file (relative to `dir`, where it was printed).
void expect_runs_as_printed(const std::string& cmd, const fs::path& dir) {
    size_t pos = 0;
    const std::string first = shell_word(cmd, pos);
    const fs::path exe = fs::path(first).is_absolute() ? fs::path(first) : dir / first;
    EXPECT_NE(first, "iblcheck") << "not on PATH here: " << cmd;
    EXPECT_TRUE(fs::is_regular_file(exe) && ::access(exe.c_str(), X_OK) == 0) << cmd;
    EXPECT_TRUE(fs::equivalent(exe, kCli)) << cmd;
}

class OwnEnvironment : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = testutil::temp_dir("own_environment");
        fs::create_directories(dir_ / "hdri");
        fs::create_directories(dir_ / "g/baseline");
        write_hdri(dir_ / "hdri/sky.exr", 1.0f);
        // The suite names the file relative to itself; the test is a 32x32 sphere judged against its
        // baseline and against the truth.
        testutil::write_file(dir_ / "suite/mine.json", R"({"suite": "mine", "tests": [{"scene": "sphere", "method": "mobile",
            "env": "../hdri/sky.exr", "size": "32x32", "baseline_tolerances": {"flip.mean": {"max": 0.001}},
            "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.002}}}]})");
    }
    void TearDown() override { fs::remove_all(dir_); }
    // Runs `args` in the temporary folder.
    int cli(const std::string& args, std::string& out) const {
        return testutil::run_command("cd " + dir_.string() + " && " + args, out);
    }
    int run(std::string& out) const { return cli(kCli + " run --suite suite/mine.json --goldens g --out o --force", out); }
    fs::path dir_;
};

TEST_F(OwnEnvironment, HdriToTruthToBlessToAPassingRunThenMissingTruthAndEditedHdriAreErrors) {
    const std::string test = "mobile.sphere.sky.exr.size=32x32";
    std::string out;
    // The test's name holds the file's name, not its absolute path.
    ASSERT_EQ(cli(kCli + " run --suite suite/mine.json --list", out), 0) << out;
    EXPECT_EQ(out, test + "\n");

    // No truth yet: an error (exit 2) naming the golden the runner reads and the command that makes it.
    EXPECT_EQ(run(out), 2) << out;
    EXPECT_NE(out.find("g/reference/sphere__sky.exr__32x32.exr: no reference golden"), std::string::npos) << out;
    const std::string truth = between(out, "no reference golden", "create it with: ", " (or set");
    ASSERT_NE(truth.find(" truth --scene sphere --env " + (dir_ / "hdri/sky.exr").string() + " --size 32x32 --goldens g"),
              std::string::npos)
        << out;
    expect_runs_as_printed(truth, dir_);

    // The printed truth command writes into the golden store, under that key; its sidecar names the
    // environment by its file name and records its content hash.
    ASSERT_EQ(cli(truth, out), 0) << out;
    EXPECT_NE(out.find("wrote g/reference/sphere__sky.exr__32x32.exr"), std::string::npos) << out;
    const json ref = json::parse(testutil::read_text(dir_ / "g/reference/sphere__sky.exr__32x32.json"));
    EXPECT_EQ(ref["env"]["spec"], "sky.exr");
    ASSERT_TRUE(ref["env"]["content_hash"].is_string());

    // The printed bless command approves the baseline; its sidecar has the same hash and no folder.
    ASSERT_EQ(run(out), 1) << out; // missing-golden: no baseline yet
    const json first = json::parse(testutil::read_text(dir_ / "o/results.json"));
    const std::string bless = first["tests"][0]["bless_command"];
    expect_runs_as_printed(bless, dir_);
    ASSERT_EQ(cli(bless, out), 0) << out;
    const json base = json::parse(testutil::read_text(dir_ / "g/baseline" / (test + ".json")));
    EXPECT_EQ(base["env"], "sky.exr");
    EXPECT_EQ(base["env_hash"], ref["env"]["content_hash"]);
    EXPECT_EQ(base["command"].get<std::string>().rfind("iblcheck bless ", 0), 0u) << base["command"]; // portable

    // A passing run, compared with the truth.
    ASSERT_EQ(run(out), 0) << out;
    EXPECT_NE(out.find("pass "), std::string::npos) << out;
    EXPECT_NE(out.find(test + "  vs truth 0."), std::string::npos) << out;
    const json passed = json::parse(testutil::read_text(dir_ / "o/results.json"));
    EXPECT_EQ(passed["tests"][0]["accuracy"]["golden"], "reference/sphere__sky.exr__32x32.exr");
    EXPECT_EQ(passed["tests"][0]["env"], "sky.exr");

    // The truth deleted: an error again, not a pass without a truth comparison.
    fs::rename(dir_ / "g/reference/sphere__sky.exr__32x32.exr", dir_ / "saved.exr");
    EXPECT_EQ(run(out), 2) << out;
    EXPECT_NE(out.find("sphere__sky.exr__32x32.exr: no reference golden"), std::string::npos) << out;
    fs::rename(dir_ / "saved.exr", dir_ / "g/reference/sphere__sky.exr__32x32.exr");

    // The HDRI edited (10 % brighter): detected by its content hash, naming the file; bless refuses too.
    write_hdri(dir_ / "hdri/sky.exr", 1.1f);
    EXPECT_EQ(run(out), 2) << out;
    EXPECT_NE(out.find((dir_ / "hdri/sky.exr").string() + ": its content changed since g/baseline/" + test + ".exr"),
              std::string::npos)
        << out;
    EXPECT_EQ(cli(bless, out), 2) << out;
    EXPECT_NE(out.find(": its content changed since g/reference/sphere__sky.exr__32x32.exr was made from it"), std::string::npos)
        << out;
}

TEST_F(OwnEnvironment, ASuiteNamesAnEnvironmentFileAndRefusesABuiltInName) {
    std::string out;
    testutil::write_file(dir_ / "suite/named.json", R"({"suite": "named", "tests": [{"scene": "sphere", "method": "mobile",
        "env": {"file": "../hdri/sky.exr", "name": "team_sky"}, "measure_only": true}]})");
    ASSERT_EQ(cli(kCli + " run --suite suite/named.json --list", out), 0) << out;
    EXPECT_EQ(out, "mobile.sphere.team_sky.default\n");
    // The truth command takes the same name and writes the key the runner reads.
    const std::string truth = kCli + " truth --scene sphere --env hdri/sky.exr --env-name team_sky --size 8x8 --goldens g";
    ASSERT_EQ(cli(truth, out), 0) << out;
    EXPECT_TRUE(fs::exists(dir_ / "g/reference/sphere__team_sky__8x8.exr")) << out;
    // A name that would take a built-in environment's goldens, or a path, is refused naming the key.
    for (const std::string bad : {"studio", "a/b"}) {
        testutil::write_file(dir_ / "suite/bad.json", R"({"suite": "bad", "tests": [{"scene": "sphere", "method": "mobile",
            "env": {"file": "../hdri/sky.exr", "name": ")" +
                                                          bad + R"("}, "measure_only": true}]})");
        EXPECT_EQ(cli(kCli + " run --suite suite/bad.json --list", out), 2) << out;
        EXPECT_NE(out.find("tests[0].env.name"), std::string::npos) << out;
    }
}

} // namespace
} // namespace test_own_environment
