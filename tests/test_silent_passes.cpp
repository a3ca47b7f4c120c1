// Issue 30, "Hostile input and faults": a test that judges nothing, a baseline sidecar without what
// the test judges, a missing reference golden, a malformed golden root or golden, and bisect's exit
// codes. Each test here failed on the code before its fix.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "harness/bless.h"
#include "harness/golden_store.h"
#include "harness/runner.h"
#include "harness/suite.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/image_compare.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_silent_passes {

namespace {

// The message load_suite gives for `text`, or "(loaded)".
std::string suite_error(const fs::path& dir, const std::string& text) {
    const fs::path f = dir / "s.json";
    write_file(f, text);
    try {
        load_suite(f.string());
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

} // namespace

TEST(SilentPasses, ATestThatJudgesNothingIsAnErrorInTheSuite) {
    // Each of these passed (or was "improved", by its cost) with a shader writing vec4(0).
    const fs::path dir = temp_dir("judges_nothing");
    const std::string head = R"({"suite": "x", "tests": [{"scene": "sphere", "method": "mobile")";
    for (const std::string& entry : {std::string(""), std::string(R"(, "baseline_tolerances": {})"),
                                     std::string(R"(, "baseline": false, "reference": false)"),
                                     std::string(R"(, "baseline": false, "reference_band": {"flip.mean": {"above": 0.1}})"),
                                     std::string(R"(, "baseline_tolerances": {"flip.mean": null}, "measure_only": false)")}) {
        const std::string err = suite_error(dir, head + entry + "}]}");
        EXPECT_NE(err.find((dir / "s.json").string() + ": tests[0]: mobile.sphere.studio.default judges nothing of its image"),
                  std::string::npos)
            << entry << ": " << err;
    }
    // A bound, a band with a baseline, or a temporal check judges it; measure_only says it is on purpose.
    EXPECT_EQ(suite_error(dir, head + R"(, "baseline_tolerances": {"ssim.mean": {"min": 0.99}}}]})"), "(loaded)");
    EXPECT_EQ(suite_error(dir, head + R"(, "reference_band": {"flip.mean": {"above": 0.1}}}]})"), "(loaded)");
    EXPECT_EQ(suite_error(dir, head + R"(, "baseline": false, "measure_only": true}]})"), "(loaded)");
    const std::string err =
        suite_error(dir, head + R"(, "baseline_tolerances": {"ssim.mean": {"min": 0.9}}, "measure_only": true}]})");
    EXPECT_NE(err.find("tests[0].measure_only: mobile.sphere.studio.default judges its image"), std::string::npos) << err;
    // The shipped suites: nightly's measurements say so; every other test judges its image.
    for (const char* name : {"ci", "nightly", "stability", "temporal"}) {
        const Suite s = load_suite(name);
        for (const TestCase& t : s.tests)
            EXPECT_EQ(t.measure_only, std::string(name) == "nightly" && !t.temporal.frames) << t.name;
    }
    fs::remove_all(dir);
}

namespace {

const char* kMiniSuite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1}}},
  "tests": [{"scene": "furnace", "method": "mobile"}]
})";
const std::string& kMiniTest = kFurnaceTest;

// A private golden root: the furnace's reference golden and a freshly blessed baseline.
struct Mini : FurnaceStore {
    explicit Mini(const std::string& name) : FurnaceStore(name, kMiniSuite) { EXPECT_EQ(bless_all(), kExitPass); }
    fs::path reference() const { return goldens / "reference" / "furnace__constant-1.exr"; }
    // The one test's verdict and message; the run's exit code in `exit_code`.
    json run(int& exit_code) const {
        RunOptions o;
        o.suite = suite.string();
        o.goldens = goldens;
        o.quiet = true;
        RunSummary s = run_suite(o);
        exit_code = s.exit_code();
        return s.results["tests"][0];
    }
    void edit_sidecar(const std::function<void(json&)>& edit) const {
        json side = json::parse(read_text(sidecar()));
        edit(side);
        write_file(sidecar(), side.dump(2));
    }
    std::string cli(const std::string& args) const {
        return built("iblcheck") + " " + args + " --suite " + suite.string() + " --goldens " + goldens.string();
    }
};

// Expects the run to be an input error (verdict error, exit 2) whose message holds `what`.
void expect_input_error(const Mini& m, const std::string& what, const std::string& why) {
    int rc = -1;
    const json t = m.run(rc);
    EXPECT_EQ(t["verdict"], "error") << why << ": " << t["message"];
    EXPECT_EQ(rc, kExitError) << why;
    EXPECT_NE(t["message"].get<std::string>().find(what), std::string::npos) << why << ": " << t["message"];
}

} // namespace

TEST(SilentPasses, ASidecarMustCarryWhatTheTestJudges) {
    // Each of these passed with the truth check silently dropped (or, for the cost, failed as a
    // regression): now an input error naming the sidecar and the key.
    Mini m("sidecar_judges");
    int rc = -1;
    ASSERT_EQ(m.run(rc)["verdict"], "pass");
    const json good = json::parse(read_text(m.sidecar()));
    const std::string side = m.sidecar().string();
    m.edit_sidecar([](json& s) { s.erase("accuracy"); });
    expect_input_error(m, side + ": \"accuracy\" is missing (the test's reference_band judges it)", "missing");
    m.edit_sidecar([](json& s) { s["accuracy"] = "0.12"; });
    expect_input_error(m, side + ": \"accuracy\" is not an object", "a string");
    m.edit_sidecar([&](json& s) { s["accuracy"] = {{"flip.maen", good["accuracy"]["flip.mean"]}}; });
    expect_input_error(m, side + ": \"accuracy\" has no number for \"flip.mean\"", "misspelt");
    write_file(m.sidecar(), "{}");
    expect_input_error(m, side + ": \"cost\" has no number for", "{}");
    write_file(m.sidecar(), good.dump(2));
    ASSERT_EQ(m.run(rc)["verdict"], "pass");
    // A test that asks for the truth must have its reference golden: in a run and in bless.
    fs::remove(m.reference());
    expect_input_error(m, m.reference().string() + ": no reference golden, and the test asks for one", "deleted reference");
    std::string out;
    EXPECT_EQ(run_command(m.cli("bless"), out), kExitError) << out;
    EXPECT_NE(out.find("not blessed: " + m.reference().string() + ": no reference golden"), std::string::npos) << out;
    EXPECT_EQ(read_text(m.sidecar()), good.dump(2)); // nothing written
}

TEST(SilentPasses, MalformedGoldenRootsAndGoldensAreInputErrors) {
    // Each of these was exit 1, a regression (missing-golden or fail), for git bisect a bad commit.
    Mini m("malformed_goldens");
    RunOptions o;
    o.suite = m.suite.string();
    o.quiet = true;
    for (const fs::path& root : {m.dir / "nonexistent", m.dir}) {
        o.goldens = root;
        try {
            run_suite(o);
            ADD_FAILURE() << root << " was taken for a golden root";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(root.string() + ": "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("not a golden root"), std::string::npos) << e.what();
        }
    }
    const Golden g = GoldenStore(m.goldens).baselines(kMiniTest)[0];
    cv::Mat y;
    cv::extractChannel(g.image, y, 1);
    write_exr(m.baseline().string(), y); // a Y-only golden
    expect_input_error(m, m.baseline().string() + ": 1 channel(s); a golden holds R, G, B", "Y only");
    write_png((m.dir / "golden.png").string(), g.image); // a PNG named .exr
    fs::copy_file(m.dir / "golden.png", m.baseline(), fs::copy_options::overwrite_existing);
    expect_input_error(m, m.baseline().string() + ": not an OpenEXR file", "PNG named .exr");
}

TEST(SilentPasses, BisectSaysCannotTestForAnythingButAVerdict) {
    // git bisect run takes 1 and 2 as "bad": a filter matching nothing was 2, a wrong --goldens 1.
    Mini m("bisect_codes");
    std::string out;
    EXPECT_EQ(run_command(m.cli("bisect --filter 'mobile.*'"), out), 0) << out;
    EXPECT_EQ(run_command(m.cli("bisect --filter 'no.such.test'"), out), kExitCannotTest) << out;
    EXPECT_NE(out.find("cannot test: no test in suite mini matches"), std::string::npos) << out;
    EXPECT_EQ(run_command(m.cli("bisect --filter 'mobile.*'") + "/nonexistent", out), kExitCannotTest) << out;
    EXPECT_NE(out.find("not a golden root"), std::string::npos) << out;
    EXPECT_EQ(run_command(m.cli("bisect"), out), kExitCannotTest) << out; // --filter is required
    EXPECT_EQ(run_command(m.cli("bisect --filter 'mobile.*' --no-such-option"), out), kExitCannotTest) << out;
    const fs::path other = m.dir / "other_goldens"; // a golden root without this test's baseline
    fs::create_directories(other);
    fs::copy(m.goldens / "reference", other / "reference");
    EXPECT_EQ(run_command(built("iblcheck") + " bisect --filter 'mobile.*' --suite " + m.suite.string() + " --goldens " +
                              other.string(),
                          out),
              kExitCannotTest)
        << out;
    EXPECT_NE(out.find("bisect verdict: skip (125)"), std::string::npos) << out;
    fs::remove(m.sidecar()); // a corrupt golden store is no verdict either
    EXPECT_EQ(run_command(m.cli("bisect --filter 'mobile.*'"), out), kExitCannotTest) << out;
    EXPECT_NE(out.find("golden sidecar missing"), std::string::npos) << out;
}

TEST(SilentPasses, CiSuiteLabelFailsWhenItsProgramIsNotBuilt) {
    // After scripts/run.sh (the tool built, the test programs not), `ctest -L ci-suite` said "No
    // tests were found!!!" and exited 0, from the root and from build/. The guard that build/tests
    // includes adds a failing ci-suite test then; here it is pointed at a program that is absent.
    const fs::path dir = temp_dir("ci_not_built");
    const fs::path guard = fs::path(IBLCHECK_BINARY_DIR) / "tests" / "ci_suite_not_built.cmake";
    write_file(dir / "CTestTestfile.cmake",
               "set(IBLCHECK_CI_SUITE_PROGRAM \"" + (dir / "absent").string() + "\")\ninclude(\"" + guard.string() + "\")\n");
    std::string out;
    EXPECT_NE(run_command("cd " + dir.string() + " && " + IBLCHECK_CTEST + " -L ci-suite --output-on-failure", out), 0) << out;
    EXPECT_NE(out.find("ci-suite.not_built"), std::string::npos) << out;
    EXPECT_NE(out.find("(test_suite_ci) is not built: run"), std::string::npos) << out;
    EXPECT_NE(out.find("scripts/build.sh --all"), std::string::npos) << out;
    EXPECT_EQ(out.find("No tests were found"), std::string::npos) << out;
    // This build has the program: the label holds the suite's tests and no guard.
    EXPECT_EQ(run_command(std::string("cd ") + IBLCHECK_BINARY_DIR + " && " + IBLCHECK_CTEST + " -N -L ci-suite", out), 0) << out;
    EXPECT_EQ(out.find("not_built"), std::string::npos) << out;
    EXPECT_NE(out.find("suite.ci.mobile.roughness_sweep.studio.default"), std::string::npos) << out;
    fs::remove_all(dir);
}

TEST(SilentPasses, ATemporalTruthCheckWithoutItsGoldenIsAnInputError) {
    // It was missing-golden (exit 1, bisect "bad") with "approve: iblcheck bless ...", which writes
    // nothing for a test without baselines.
    const fs::path dir = temp_dir("temporal_truth");
    write_file(dir / "tt.json", R"({"suite": "tt", "tests": [{"scene": "bumpy_sphere", "method": "mobile", "env": "sky_sun",
        "size": "64x32", "baseline": false, "reference": false,
        "temporal": {"frames": 2, "reference_ssaa": 2, "checks": {"truth_flip_mean": {"max": 1.0}}}}]})");
    RunOptions o;
    o.suite = (dir / "tt.json").string();
    o.quiet = true;
    const RunSummary s = run_suite(o);
    const json& t = s.results["tests"][0];
    EXPECT_EQ(t["verdict"], "error") << t["message"];
    EXPECT_EQ(s.exit_code(), kExitError);
    const std::string golden = GoldenStore().reference_sequence_path(load_suite(o.suite).tests[0].spec, 2).string();
    EXPECT_NE(t["message"].get<std::string>().find(golden + ": no temporal truth golden"), std::string::npos) << t["message"];
    fs::remove_all(dir);
}

TEST(SilentPasses, AGoldenWithAHugeFinitePixelPassesABitIdenticalRender) {
    // The runner's and bless's comparison (metrics/image_compare.h): SSIM was NaN for a golden with one pixel
    // at 1e20, so a bit-identical render failed it forever; against another render FLIP saw nothing.
    const Golden g = GoldenStore().baselines("mobile.roughness_sweep.studio.default")[0];
    cv::Mat hot = g.image.clone();
    hot.at<cv::Vec3f>(40, 100) = cv::Vec3f(1e20f, 1e20f, 1e20f);
    const std::map<std::string, Bound> tolerances = load_suite("ci").tests[0].baseline_tolerances;
    const Comparison same = judge_baseline(compare_images(hot, hot, 1), tolerances);
    EXPECT_EQ(same.verdict, Verdict::pass) << same.message;
    EXPECT_EQ(same.metrics["ssim"]["mean"], 1.0);
    const Comparison other = judge_baseline(compare_images(g.image, hot, 1), tolerances);
    EXPECT_EQ(other.verdict, Verdict::fail) << other.metrics.dump();
    EXPECT_GT(other.metrics["flip"]["max"].get<double>(), 0.5);
}
} // namespace test_silent_passes
