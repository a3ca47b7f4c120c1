// The findings at the top of a nightly report (reports/nightly_findings.h, issue 26): the words and
// numbers come from the results, the history and the explain/explore files, worked here by hand.
#include <gtest/gtest.h>

#include <regex>

#include "kernel/errors.h"
#include "report_fixture.h"
#include "reports/nightly_findings.h"
#include "reports/report_html.h"
#include "reports/report_writer.h"
#include "test_support.h"

namespace iblcheck::report {
namespace {

using json = nlohmann::json;

json test_json(const std::string& env, const std::string& variant, double flip, double ipp) {
    json t = {{"name", "mobile.roughness_sweep." + env + (variant.empty() ? "" : "." + variant)},
              {"scene", "roughness_sweep"},
              {"method", "mobile"},
              {"env", env},
              {"variant", variant},
              {"verdict", "pass"},
              {"accuracy", {{"flip_mean", flip}}},
              {"cost", {{"spirv_instructions_per_pixel", ipp}}}};
    return t;
}

json nightly_results() {
    json r = {{"suite", "nightly"}, {"commit", "c9"}, {"date", "2026-11-26T03:00:00Z"}, {"tests", json::array()}};
    r["tests"].push_back(test_json("studio", "default", 0.20, 1000));                // a run's name; sky_sun's "" (older runs)
    r["tests"].push_back(test_json("studio", "diffuse=irradiance_cube", 0.16, 950)); // <= default: the best there
    r["tests"].push_back(test_json("studio", "dominant_dir=lagarde", 0.15, 1080));   // +8 %: the best within +10 %
    r["tests"].push_back(test_json("studio", "normalization=ue4", 0.22, 1040));      // worst
    r["tests"].push_back(test_json("studio", "specular_aa=tokuyoshi", 0.14, 1600));  // +60 %
    r["tests"].push_back(test_json("sky_sun", "", 0.30, 1000));
    return r;
}

// Two spheres, three rungs: split_sum +0.10/+0.30, env_brdf_approx +0.02/-0.01, diffuse +0.05/0.
json budget() {
    auto fig = [](double a, double b, double img) {
        return json{{"image", {{"flip", img}}},
                    {"spheres", json::array({{{"flip", a}, {"label", "metal r=0"}}, {{"flip", b}, {"label", "metal r=1"}}})}};
    };
    json rungs = json::array();
    rungs.push_back({{"key", "split_sum"}, {"label", "split sum, exact parts (n = v = R)"}, {"share", fig(0.10, 0.30, 0.20)}});
    rungs.push_back(
        {{"key", "env_brdf_approx"}, {"label", "EnvBRDFApprox for the exact DFG"}, {"share", fig(0.02, -0.01, 0.005)}});
    rungs.push_back({{"key", "diffuse"}, {"label", "diffuse irradiance_cube -> sh9"}, {"share", fig(0.05, 0.0, 0.025)}});
    return {{"scene", "roughness_sweep"},
            {"env", "studio"},
            {"rungs", rungs},
            {"total", fig(0.17, 0.29, 0.23)},
            {"interaction", fig(0, 0, -0.001)}};
}

struct Page {
    std::string html;
};

Page page(const json& results, const std::vector<json>& history, const std::vector<json>& findings) {
    const auto dir = testutil::temp_dir("findings");
    html::ImageStore images(dir, dir / "out");
    return {findings_html(results, history, findings, images)};
}

TEST(NightlyFindings, LargestShareBestPerCostBandAccuracyAndBestWorstVariantsInWords) {
    const std::string o = page(nightly_results(), {}, {budget()}).html;
    // The largest share: split_sum, 0.2 of 0.23 (87 %).
    EXPECT_NE(
        o.find(
            "Under studio, the largest share of error is split sum, exact parts (n = v = R): 0.2 of the mean FLIP 0.23 (87 %)"),
        std::string::npos)
        << o;
    // Best within +10 %: lagarde (-25 % FLIP); best and worst variants against the default.
    EXPECT_NE(o.find("within +10 % of the default's instructions, dominant_dir=lagarde is the most accurate (-25.0 % FLIP)"),
              std::string::npos)
        << o;
    EXPECT_NE(o.find("the best variant specular_aa=tokuyoshi (0.14, -30.0 %), the worst normalization=ue4 (+10.0 %)"),
              std::string::npos)
        << o;
    // The bands (ceilings) of studio: <= default: the irradiance cube; <= +10 % and <= +50 %: lagarde;
    // any cost: tokuyoshi.
    const std::regex row("diffuse=irradiance_cube <b>0.16</b>.*<td>dominant_dir=lagarde <b>0.15</b>.*<td>dominant_dir=lagarde "
                         "<b>0.15</b>.*<td>specular_aa=tokuyoshi <b>0.14</b>");
    EXPECT_TRUE(std::regex_search(o, row)) << o;
    // sky_sun has only its default: no best/worst sentence, but a row in the accuracy table.
    EXPECT_EQ(o.find("under sky_sun: the mobile default"), std::string::npos);
    EXPECT_NE(o.find("<td>sky_sun</td><td class=\"num\">1</td><td class=\"num\">0.3</td>"), std::string::npos) << o;
    EXPECT_NE(o.find("No earlier run to compare with"), std::string::npos);
}

TEST(NightlyFindings, StackedBarsHaveASegmentPerNonZeroShareSignedAboutZero) {
    const std::string svg = budget_bars_svg(budget());
    EXPECT_NE(svg.find("data-chart=\"budget-studio\" data-points=\"2\""), std::string::npos) << svg;
    size_t segs = 0;
    for (size_t p = 0; (p = svg.find("class=\"seg\"", p)) != std::string::npos; ++p) ++segs;
    EXPECT_EQ(segs, 5u); // 3 shares on r=0, 2 non-zero on r=1
    // Scale: top 0.30 (r=1's positive stack), bottom -0.01: 100 px over 0.31. The r=1 split_sum
    // segment is 0.30 * 100 / 0.31 = 96.77 px tall; env_brdf_approx's -0.01 is 3.23 px below zero.
    EXPECT_NE(svg.find("height=\"96.77\" fill=\"#1c7ed6\"><title>metal r=1"), std::string::npos) << svg;
    EXPECT_NE(svg.find("height=\"3.23\" fill=\"#f59f00\"><title>metal r=1"), std::string::npos) << svg;
    // One material: one row, the second sphere one pitch (30) to the right of the first, bars 18 wide.
    EXPECT_NE(svg.find("x=\"6.0\" y=\"70.52\" width=\"18\" height=\"32.26\" fill=\"#1c7ed6\"><title>metal r=0"),
              std::string::npos)
        << svg;
    EXPECT_NE(svg.find("x=\"36.0\" y=\"6.00\" width=\"18\" height=\"96.77\""), std::string::npos) << svg;
    // Two materials: two rows, both starting at the left edge, the second 130 px lower.
    json two = budget();
    two["total"]["spheres"][1]["metallic"] = 1.0;
    const std::string rows = budget_bars_svg(two, 48);
    EXPECT_NE(rows.find("x=\"9.6\" y=\"136.00\" width=\"29\" height=\"96.77\""), std::string::npos) << rows;
}

TEST(NightlyFindings, SinceTheLastRunCountsMovesBeyondTheNoiseFloorAndCostChanges) {
    json prev = {{"suite", "nightly"}, {"commit", "c8"}, {"date", "2026-11-25T03:00:00Z"}, {"tests", json::object()}};
    prev["tests"]["mobile.roughness_sweep.studio.default"] = {{"flip_mean", 0.20005}, {"spirv_ipp", 1000}}; // within 1e-4
    prev["tests"]["mobile.roughness_sweep.studio.dominant_dir=lagarde"] = {{"flip_mean", 0.17}, {"spirv_ipp", 1080}}; // moved
    prev["tests"]["mobile.roughness_sweep.studio.normalization=ue4"] = {{"flip_mean", 0.22}, {"spirv_ipp", 1000}};    // cost
    prev["tests"]["mobile.roughness_sweep.interior"] = {{"flip_mean", 0.1}};                                          // gone
    const std::string o = page(nightly_results(), {prev}, {}).html;
    EXPECT_NE(
        o.find("Since the last run (commit c8, 2026-11-25T03:00:00Z): 1 test(s) moved in accuracy beyond their noise floor, 1 "
               "changed their instruction count, 3 added, 1 gone."),
        std::string::npos)
        << o;
    EXPECT_NE(o.find("0.17 &rarr; 0.15 (-11.8 %)"), std::string::npos) << o;
    EXPECT_NE(o.find("No error budget given"), std::string::npos);
}

TEST(NightlyFindings, OnlyANightlyOrAPageGivenFindingsGetsTheSectionAndBadFilesAreNamed) {
    json ci = nightly_results();
    ci["suite"] = "ci";
    EXPECT_FALSE(findings_wanted(ci, {}));
    EXPECT_TRUE(findings_wanted(ci, {budget()}));
    EXPECT_TRUE(findings_wanted(nightly_results(), {}));
    const auto dir = testutil::temp_dir("findings_files");
    testutil::write_file(dir / "bad.json", "{not json");
    testutil::write_file(dir / "other.json", R"({"suite": "ci"})");
    for (const char* f : {"bad.json", "other.json", "missing.json"}) {
        try {
            read_findings(dir / f);
            ADD_FAILURE() << f;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find((dir / f).string()), std::string::npos) << e.what();
        }
    }
    testutil::write_file(dir / "b.json", budget().dump());
    EXPECT_EQ(read_findings(dir / "b.json")["env"], "studio");
}

// The page: a nightly run's report has the findings between the summary and the tabs; a ci run's
// has none unless --findings names a file.
TEST(NightlyFindings, TheNightlyPageHasTheFindingsAtTheTopAndCiHasNone) {
    const auto dir = testutil::temp_dir("findings_page");
    testutil::CiRun run = testutil::make_ci_run(dir / "run", 2, false);
    write_report(run.results, run.dir, dir / "ci");
    EXPECT_EQ(testutil::read_text(dir / "ci" / "index.html").find("id=\"findings\""), std::string::npos);
    run.results["suite"] = "nightly";
    write_report(run.results, run.dir, dir / "nightly");
    const std::string page = testutil::read_text(dir / "nightly" / "index.html");
    const size_t findings = page.find("<section class=\"findings\" id=\"findings\">"), tabs = page.find("<nav class=\"tabs\">");
    ASSERT_NE(findings, std::string::npos);
    EXPECT_LT(page.find("</header>"), findings);
    EXPECT_LT(findings, tabs);
}

// The command line: `iblcheck report --findings` puts an explain budget on a ci run's page; a file
// that is neither explain's nor explore's is exit 2 naming it, and no page is written.
TEST(NightlyFindings, ReportFindingsFlagReadsTheFileOrNamesItInAnExit2) {
    const auto dir = testutil::temp_dir("findings_cli");
    testutil::make_ci_run(dir / "run", 2, false);
    testutil::write_file(dir / "b.json", budget().dump());
    testutil::write_file(dir / "bad.json", R"({"suite": "ci"})");
    const std::string cli = testutil::built("iblcheck") + " report " + (dir / "run" / "results.json").string() + " --out ";
    std::string out;
    ASSERT_EQ(testutil::run_command(cli + (dir / "ok").string() + " --findings " + (dir / "b.json").string(), out), 0) << out;
    EXPECT_NE(testutil::read_text(dir / "ok" / "index.html").find("Under studio, the largest share of error is split sum"),
              std::string::npos);
    EXPECT_EQ(testutil::run_command(cli + (dir / "bad").string() + " --findings " + (dir / "bad.json").string(), out), 2) << out;
    EXPECT_NE(out.find((dir / "bad.json").string() + ": neither an `iblcheck explain --json` budget"), std::string::npos) << out;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad" / "index.html"));
}

} // namespace
} // namespace iblcheck::report
