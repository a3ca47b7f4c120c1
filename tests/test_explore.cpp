// `iblcheck explore` (issue 26): the coordinate descent, its fronts and its axes, on a synthetic
// option space whose figures are worked by hand (no GPU), so every path and front is known.
#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "harness/explore.h"
#include "kernel/errors.h"
#include "renderers/option_table.h"
#include "test_support.h"

namespace iblcheck {
namespace {

// FLIP and cost of a configuration: a base, each option's own change, and an interaction that makes
// dominant_dir=lagarde pay only with the irradiance cube (so one change at a time misses it).
ExplorePoint synthetic(const OptionMap& o) {
    ExplorePoint p;
    p.flip = 0.30, p.ipp = 1000, p.fetches = 3, p.bytes = 1000;
    const bool cube = option_choice(o, "diffuse") == "irradiance_cube";
    const std::string dom = option_choice(o, "dominant_dir");
    if (cube) p.flip -= 0.04, p.ipp -= 50, p.fetches += 1, p.bytes += 100;
    if (dom == "lagarde") p.flip += cube ? -0.08 : 0.01, p.ipp += 60;
    if (dom == "filament") p.flip -= 0.02, p.ipp += 300; // more accurate alone, but over the budget
    if (option_choice(o, "storage") == "rgbm8") p.flip += 0.001, p.bytes -= 500;
    return p;
}

std::vector<ExploreAxis> synthetic_axes() {
    return {{"dominant_dir", {"off", "lagarde", "filament"}},
            {"diffuse", {"sh9", "irradiance_cube"}},
            {"storage", {"rgba16f", "rgbm8"}}};
}

std::vector<std::string> names(const std::vector<ExplorePoint>& pts, const std::vector<size_t>& idx) {
    std::vector<std::string> out;
    for (size_t i : idx) out.push_back(pts[i].name());
    return out;
}

TEST(Explore, DescentFindsTheCombinationOneChangeAtATimeMissesWithinTheBudget) {
    int calls = 0;
    const ExploreResult r = explore_descent(
        synthetic_axes(), [&](const OptionMap& o) { return ++calls, synthetic(o); }, 0.10, 3);
    // Pass 1: dominant_dir: lagarde alone is worse (0.31), filament over the budget (1300 > 1100):
    // stays off. diffuse -> irradiance_cube (0.26). storage: rgbm8 worse. Pass 2: dominant_dir ->
    // lagarde (0.18 at 1010 instr/px). Pass 3: nothing moves.
    ASSERT_EQ(r.moves.size(), 2u);
    EXPECT_EQ(r.moves[0].key, "diffuse");
    EXPECT_EQ(r.moves[0].pass, 1);
    EXPECT_EQ(r.moves[1].key, "dominant_dir");
    EXPECT_EQ(r.moves[1].to, "lagarde");
    EXPECT_EQ(r.moves[1].pass, 2);
    EXPECT_EQ(r.passes, 3);
    EXPECT_EQ(r.best.name(), "diffuse=irradiance_cube,dominant_dir=lagarde");
    EXPECT_NEAR(r.best.flip, 0.18, 1e-12);
    EXPECT_DOUBLE_EQ(r.ipp_budget, 1100);
    EXPECT_EQ(r.grid_size, 12);
    EXPECT_EQ(calls, int(r.evaluated.size())); // each configuration rendered once
    EXPECT_EQ(r.evaluated.size(), 8u);
    const nlohmann::json j = explore_json(r, synthetic_axes());
    EXPECT_EQ(j["not_tried"].get<double>(), 4);
    EXPECT_NEAR(j["flip_reduction"].get<double>(), 0.4, 1e-12);
    EXPECT_TRUE(j["target_met"].get<bool>());
    EXPECT_NE(explore_table(j).find("not tried: 4"), std::string::npos);
}

TEST(Explore, FrontsAreTheUndominatedPointsInCostOrderAndTheSameOnARerun) {
    const ExploreResult a = explore_descent(synthetic_axes(), synthetic, 0.10, 3);
    const ExploreResult b = explore_descent(synthetic_axes(), synthetic, 0.10, 3);
    const auto fa = explore_front(a.evaluated, ExploreCost::instructions);
    EXPECT_EQ(names(a.evaluated, fa), names(b.evaluated, explore_front(b.evaluated, ExploreCost::instructions)));
    // Instructions: irradiance cube alone (950, 0.26; with rgbm8 the same cost at a worse FLIP), and
    // with lagarde (1010, 0.18). Filament (1300, 0.28) and the default (1000, 0.30) are beaten.
    EXPECT_EQ(names(a.evaluated, fa),
              (std::vector<std::string>{"diffuse=irradiance_cube", "diffuse=irradiance_cube,dominant_dir=lagarde"}));
    // Bytes: rgbm8 was only rendered with the cube; with lagarde too it is the cheapest (600 bytes,
    // 0.181), and the same without rgbm8 the most accurate (1100, 0.18).
    EXPECT_EQ(names(a.evaluated, explore_front(a.evaluated, ExploreCost::bytes)),
              (std::vector<std::string>{"diffuse=irradiance_cube,dominant_dir=lagarde,storage=rgbm8",
                                        "diffuse=irradiance_cube,dominant_dir=lagarde"}));
}

TEST(Explore, EqualPointsLeaveOneOnTheFront) {
    std::vector<ExplorePoint> pts(3);
    pts[0].flip = 0.2, pts[0].ipp = 10;
    pts[1].flip = 0.2, pts[1].ipp = 10;
    pts[2].flip = 0.1, pts[2].ipp = 20;
    EXPECT_EQ(explore_front(pts, ExploreCost::instructions), (std::vector<size_t>{0, 2}));
}

TEST(Explore, NoMoveWithinTheBudgetSaysTheTargetIsNotMet) {
    const ExploreResult r = explore_descent({{"dominant_dir", {"off", "filament"}}}, synthetic, 0.10, 3);
    EXPECT_TRUE(r.moves.empty());
    EXPECT_EQ(r.best.name(), "default");
    const nlohmann::json j = explore_json(r, {{"dominant_dir", {"off", "filament"}}});
    EXPECT_FALSE(j["target_met"].get<bool>());
    EXPECT_NE(explore_table(j).find("none: no value of any axis beat the default"), std::string::npos);
}

TEST(Explore, AxesAreCheckedAgainstTheOptionTable) {
    EXPECT_EQ(parse_explore_axis("diffuse=sh9|irradiance_cube").values, (std::vector<std::string>{"sh9", "irradiance_cube"}));
    EXPECT_EQ(parse_explore_axis("cube_size=64|128").values.size(), 2u);
    EXPECT_THROW(parse_explore_axis("diffuse=sh9|cube"), UsageError); // unknown value
    EXPECT_THROW(parse_explore_axis("samples=64|128"), UsageError);   // the sampled method's
    EXPECT_THROW(parse_explore_axis("diffuse"), UsageError);          // no values
    EXPECT_THROW(parse_explore_axis("diffuse=sh9||irradiance_cube"), UsageError);
    EXPECT_THROW(explore_descent({{"diffuse", {"sh9"}}, {"diffuse", {"sh9"}}}, synthetic, 0.1, 1), UsageError);
    EXPECT_THROW(explore_descent({{"diffuse", {"sh9", "sh9"}}}, synthetic, 0.1, 1), UsageError);
    EXPECT_THROW(explore_descent({{"mips", {"4"}}}, synthetic, 0.1, 1), UsageError); // no default value to start from
}

// The real command on a tiny space (the sphere, 128x128, against its reference golden: four renders
// a run): a rerun renders the same figures and gives the same fronts, and the winners' suite names
// the winner. The real search (default axes, the roughness sweep) is a command, not a test.
TEST(ExploreCli, TinySpaceGivesTheSameFrontOnARerunAndWritesTheWinnersSuite) {
    const auto dir = testutil::temp_dir("explore_cli");
    const std::string cmd = std::string(IBLCHECK_BINARY_DIR) +
                            "/iblcheck explore --scene sphere --env studio --axis 'diffuse=sh9|irradiance_cube' --axis "
                            "'dominant_dir=off|lagarde' --passes 2 --json ";
    std::string out;
    ASSERT_EQ(testutil::run_command(cmd + (dir / "a.json").string() + " --suite-out " + (dir / "s.json").string(), out), 0)
        << out;
    ASSERT_EQ(testutil::run_command(cmd + (dir / "b.json").string(), out), 0) << out;
    const auto a = nlohmann::json::parse(testutil::read_text(dir / "a.json"))["environments"][0];
    const auto b = nlohmann::json::parse(testutil::read_text(dir / "b.json"))["environments"][0];
    EXPECT_EQ(a["front"], b["front"]);
    EXPECT_EQ(a["evaluated"], b["evaluated"]);
    EXPECT_EQ(a["best"], b["best"]);
    EXPECT_GE(a["evaluated"].size(), 3u);
    EXPECT_GT(a["start"]["flip"].get<double>(), 0.01); // a real figure against the truth
    EXPECT_GT(a["start"]["ipp"].get<double>(), 1000.0);
    EXPECT_EQ(a["truth"].get<std::string>(), "reference/sphere__studio.exr");
    const auto suite = nlohmann::json::parse(testutil::read_text(dir / "s.json"));
    EXPECT_EQ(suite["tests"][0]["options"], a["best"]["options"]);
    EXPECT_EQ(suite["tests"][0]["env"], "studio");
    // An existing output is not overwritten unasked; a bad axis is exit 2 naming it.
    EXPECT_EQ(testutil::run_command(cmd + (dir / "a.json").string(), out), 2) << out;
    EXPECT_EQ(testutil::run_command(testutil::built("iblcheck") + " explore --axis 'diffuse=sh9|cube'", out), 2);
    EXPECT_NE(out.find("unknown value 'cube'"), std::string::npos) << out;
}

} // namespace
} // namespace iblcheck
