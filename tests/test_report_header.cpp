// The summary's "since the baselines" (reports/since_baselines.cpp, issue 32): a clean main whose
// baselines were blessed at another commit and before some shader file changed shows no red; the
// shader files that differ from what a failing test's baseline was blessed with are named, by file.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "reports/report_writer.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report_header {

namespace {

std::string header_of(const fs::path& index) {
    std::ifstream f(index);
    const std::string html((std::istreambuf_iterator<char>(f)), {});
    return html.substr(html.find("<header"), html.find("</header>") - html.find("<header"));
}

} // namespace

TEST(ReportHeader, CleanMainBlessedAtAnotherCommitAndShaderTreeShowsNoRed) {
    const fs::path dir = testutil::temp_dir("header_clean");
    testutil::CiRun run = testutil::make_ci_run(dir / "run", 12, 0);
    // As on main: every baseline blessed at another commit, before an unrelated shader file changed.
    for (json& t : run.results["tests"]) t["comparisons"][0]["approved"]["shader_tree_hash"] = "c463237abf68cbe0";
    report::write_report(run.results, run.dir, run.dir);
    const std::string h = header_of(run.dir / "index.html");
    EXPECT_EQ(h.find("class=\"changed\""), std::string::npos) << h;
    EXPECT_EQ(h.find("overall-fail"), std::string::npos);
    EXPECT_NE(h.find("<td class=\"info\">differs for 12 of 12, all of which pass"), std::string::npos) << h;
    EXPECT_NE(h.find("<td class=\"info\">12 of 12 blessed at another commit"), std::string::npos) << h;
    fs::remove_all(dir);
}

TEST(ReportHeader, ShaderFilesThatChangedSinceTheBaselinesAreNamedByFile) {
    const fs::path dir = testutil::temp_dir("header_files");
    testutil::CiRun run = testutil::make_ci_run(dir / "run", 3, 2);
    const json same = {{"brdf.glsl", "11"}, {"mip_mapping.glsl", "22"}};
    for (json& t : run.results["tests"]) {
        const bool fail = t["verdict"] == "fail";
        t["provenance"]["shader_files"] = same;
        t["comparisons"][0]["approved"]["shader_files"] = same;
        if (fail) t["comparisons"][0]["approved"]["shader_files"]["mip_mapping.glsl"] = "21";
    }
    report::write_report(run.results, run.dir, run.dir);
    const std::string h = header_of(run.dir / "index.html");
    EXPECT_NE(h.find("<th>shader files</th><td colspan=\"2\">changed since blessed: <span class=\"mono\">mip_mapping.glsl</span> "
                     "(2 tests)</td><td class=\"changed\">1 file changed</td>"),
              std::string::npos)
        << h;
    EXPECT_EQ(h.find("<th>shader tree</th>"), std::string::npos) << "the files say it, the tree hash adds nothing";
    fs::remove_all(dir);
}

// The page's style sheet and script are the files reports/assets/report.css and report.js, embedded at
// build time byte for byte (issue 31: they were C++ raw strings in report_assets.h and report_script.h).
TEST(ReportAssets, PageCarriesTheAssetFilesByteForByte) {
    auto read = [](const fs::path& p) {
        std::ifstream f(p, std::ios::binary);
        return std::string((std::istreambuf_iterator<char>(f)), {});
    };
    const std::string css = read(fs::path(IBLCHECK_SOURCE_DIR) / "reports/assets/report.css");
    const std::string js = read(fs::path(IBLCHECK_SOURCE_DIR) / "reports/assets/report.js");
    ASSERT_GT(css.size(), 5000u);
    ASSERT_GT(js.size(), 15000u);
    const fs::path dir = testutil::temp_dir("assets");
    testutil::CiRun run = testutil::make_ci_run(dir / "run", 2, 1);
    report::write_report(run.results, run.dir, run.dir);
    const std::string html = read(run.dir / "index.html");
    EXPECT_NE(html.find("<style>\n" + css + "</style>\n</head>"), std::string::npos);
    const std::string tail = "<script>\n" + js + "</script>\n</body></html>\n";
    ASSERT_GE(html.size(), tail.size());
    EXPECT_EQ(html.substr(html.size() - tail.size()), tail);
    fs::remove_all(dir);
}
} // namespace test_report_header
