// Issue 30, "Hostile input and faults": a test that judges nothing, a baseline sidecar without what
// the test judges, a missing reference golden, a malformed golden root or golden, and bisect's exit
// codes. Each test here failed on the code before its fix.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness/bless.h"
#include "harness/common/errors.h"
#include "harness/golden_store.h"
#include "harness/runner.h"
#include "harness/suite.h"
#include "metrics/image_io.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

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
