// harness/verdict.h on plain numbers: no rendering, no files. Every rule the gate applies has its
// edges here: tolerance edges, higher-is-better metrics, the improved band, costs, any-of-several
// baselines, and NaN, which must never pass.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "harness/verdict.h"
#include "kernel/errors.h"

using namespace iblcheck;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as one unity unit (tests/CMakeLists.txt).
namespace test_verdict {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json flip_metrics(double mean, double ssim = 1.0) {
    return {{"flip", {{"mean", mean}, {"p99", mean * 4}}}, {"ssim", {{"mean", ssim}}}, {"psnr", {{"db", 40.0}}}};
}
} // namespace

TEST(Verdict, NamesRoundTripAndOrderBySeverity) {
    for (Verdict v : {Verdict::pass, Verdict::improved, Verdict::fail, Verdict::missing_golden, Verdict::error})
        EXPECT_EQ(parse_verdict(verdict_name(v)), v);
    EXPECT_EQ(verdict_name(Verdict::missing_golden), "missing-golden");
    EXPECT_THROW(parse_verdict("passed"), InputError);
    EXPECT_EQ(overall_verdict({}), Verdict::pass);
    EXPECT_EQ(overall_verdict({Verdict::pass, Verdict::improved}), Verdict::improved);
    EXPECT_EQ(overall_verdict({Verdict::improved, Verdict::fail, Verdict::pass}), Verdict::fail);
    EXPECT_EQ(overall_verdict({Verdict::fail, Verdict::missing_golden}), Verdict::missing_golden);
    EXPECT_EQ(overall_verdict({Verdict::missing_golden, Verdict::error}), Verdict::error);
    EXPECT_TRUE(is_regression(Verdict::fail));
    EXPECT_TRUE(is_regression(Verdict::missing_golden));
    EXPECT_FALSE(is_regression(Verdict::error)); // "cannot test": exit 2, bisect 125
    EXPECT_FALSE(is_regression(Verdict::improved));
}

TEST(Verdict, BoundEdgesAreInclusiveAndMessagesSayByHowMuch) {
    Bound max{std::nullopt, 0.001};
    EXPECT_EQ(judge_bound("flip.mean", 0.001, max).status, Verdict::pass);
    Check over = judge_bound("flip.mean", 0.0015, max);
    EXPECT_EQ(over.status, Verdict::fail);
    EXPECT_EQ(over.message, "flip.mean 0.0015 > 0.001 (+0.0005)");
    Bound min{0.999, std::nullopt};
    EXPECT_EQ(judge_bound("ssim.mean", 0.999, min).status, Verdict::pass);
    Check under = judge_bound("ssim.mean", 0.99, min);
    EXPECT_EQ(under.status, Verdict::fail);
    EXPECT_EQ(under.message, "ssim.mean 0.99 < 0.999 (-0.009)");
}

TEST(Verdict, NanNeverPasses) {
    EXPECT_EQ(judge_bound("ssim.mean", kNaN, Bound{0.999, std::nullopt}).status, Verdict::fail);
    EXPECT_EQ(judge_bound("flip.mean", kNaN, Bound{std::nullopt, 1.0}).status, Verdict::fail);
    EXPECT_EQ(judge_bound("flip.mean", 0.0, Bound{std::nullopt, kNaN}).status, Verdict::fail); // a NaN bound
    EXPECT_EQ(judge_bound("ssim.mean", 1.0, Bound{kNaN, std::nullopt}).status, Verdict::fail);
    EXPECT_EQ(judge_band("flip.mean", kNaN, 0.1, Band{}).status, Verdict::fail);
    EXPECT_EQ(judge_band("flip.mean", 0.1, kNaN, Band{}).status, Verdict::fail);
    EXPECT_EQ(judge_cost("cost.x", kNaN, 100, 0.25).status, Verdict::fail);
    EXPECT_EQ(judge_cost("cost.x", 100, kNaN, 0.25).status, Verdict::fail);
    // A golden whose SSIM came out NaN: the baseline comparison fails (it used to pass).
    Comparison c = judge_baseline(flip_metrics(0.0, kNaN),
                                  {{"ssim.mean", Bound{0.999, std::nullopt}}, {"flip.mean", Bound{std::nullopt, 0.001}}});
    EXPECT_EQ(c.verdict, Verdict::fail);
    EXPECT_NE(c.message.find("ssim.mean is NaN"), std::string::npos) << c.message;
    // A metric the comparison does not have reads as NaN, so its tolerance fails.
    EXPECT_TRUE(std::isnan(metric_value(flip_metrics(0.1), "flip.block_max")));
    EXPECT_TRUE(std::isnan(metric_value(json(), "flip.mean")));
    EXPECT_EQ(judge_baseline(flip_metrics(0.0), {{"flip.block_max", Bound{std::nullopt, 0.01}}}).verdict, Verdict::fail);
}

TEST(Verdict, ReferenceBandFailsOnTheWorseSideAndImprovesOnTheBetter) {
    Band band{0.2, 0.1, 0.002}; // [0.1·0.8 − 0.002, 0.1·1.1 + 0.002] = [0.078, 0.112]
    EXPECT_EQ(judge_band("accuracy.flip.mean", 0.112, 0.1, band).status, Verdict::pass);
    EXPECT_EQ(judge_band("accuracy.flip.mean", 0.0781, 0.1, band).status, Verdict::pass);
    Check worse = judge_band("accuracy.flip.mean", 0.113, 0.1, band);
    EXPECT_EQ(worse.status, Verdict::fail);
    EXPECT_NEAR(*worse.max, 0.112, 1e-12);
    Check better = judge_band("accuracy.flip.mean", 0.07, 0.1, band);
    EXPECT_EQ(better.status, Verdict::improved);
    EXPECT_NE(better.message.find("re-blessing"), std::string::npos);
    // SSIM and PSNR: higher is better, so the sides swap.
    EXPECT_TRUE(higher_is_better("accuracy.ssim.mean"));
    EXPECT_TRUE(higher_is_better("psnr.db"));
    EXPECT_FALSE(higher_is_better("flip.p99"));
    EXPECT_EQ(judge_band("accuracy.ssim.mean", 0.5, 0.9, Band{}).status, Verdict::fail);
    EXPECT_EQ(judge_band("accuracy.ssim.mean", 0.999, 0.9, Band{}).status, Verdict::improved);
    // judge_reference checks only what the baseline approved, and prefixes "accuracy.".
    Comparison r = judge_reference(flip_metrics(0.2), {{"flip.mean", 0.1}}, {{"flip.mean", band}, {"ssim.mean", Band{}}});
    ASSERT_EQ(r.checks.size(), 1u);
    EXPECT_EQ(r.checks[0].metric, "accuracy.flip.mean");
    EXPECT_EQ(r.verdict, Verdict::fail);
}

TEST(Verdict, CostMayGrowByTheToleranceAndNoMore) {
    EXPECT_EQ(judge_cost("cost.spirv_instructions_per_pixel", 1250, 1000, 0.25).status, Verdict::pass);
    Check slower = judge_cost("cost.spirv_instructions_per_pixel", 2000, 1000, 0.25);
    EXPECT_EQ(slower.status, Verdict::fail);
    EXPECT_NE(slower.message.find("+100.0 %"), std::string::npos) << slower.message;
    EXPECT_NE(slower.message.find("approved 1000 +25 %"), std::string::npos) << slower.message;
    EXPECT_EQ(judge_cost("cost.spirv_instructions_per_pixel", 1251, 1000, 0.25).status, Verdict::fail);
    EXPECT_EQ(judge_cost("cost.texture_fetches_per_pixel", 0.5, 1.0, 0.25).status, Verdict::improved);
    EXPECT_EQ(judge_cost("cost.texture_fetches_per_pixel", 0.8, 1.0, 0.25).status, Verdict::pass);
}

TEST(Verdict, AnyOfSeveralBaselinesPassesElseTheClosestIsReported) {
    std::map<std::string, Bound> tol = {{"flip.mean", Bound{std::nullopt, 0.001}}};
    std::vector<Comparison> c = {judge_baseline(flip_metrics(0.05), tol), judge_baseline(flip_metrics(0.0005), tol),
                                 judge_baseline(flip_metrics(0.0), tol)};
    EXPECT_EQ(choose_baseline(c), 1u); // the first that passes
    std::vector<Comparison> failing = {judge_baseline(flip_metrics(0.05), tol), judge_baseline(flip_metrics(0.02), tol),
                                       judge_size("baseline", 8, 8, 16, 16)};
    EXPECT_EQ(choose_baseline(failing), 1u); // the closest failing one
    Comparison size = judge_size("baseline", 528, 96, 256, 96);
    EXPECT_EQ(size.verdict, Verdict::fail);
    EXPECT_EQ(size.message, "size 528x96 but the baseline golden is 256x96");
}

TEST(Verdict, JsonHasTheResultsFormatKeys) {
    Check c = judge_bound("flip.mean", 0.5, Bound{std::nullopt, 0.001});
    json j = to_json(c);
    EXPECT_EQ(j["metric"], "flip.mean");
    EXPECT_EQ(j["status"], "fail");
    EXPECT_TRUE(j["min"].is_null());
    EXPECT_EQ(j["max"], 0.001);
    // NaN values become null (JSON has no NaN); the status still says fail.
    EXPECT_TRUE(to_json(judge_bound("ssim.mean", kNaN, Bound{0.9, std::nullopt}))["value"].is_null());
    Comparison cmp = judge_size("reference", 1, 2, 3, 4);
    cmp.golden = "reference/x.exr";
    json jc = to_json(cmp);
    EXPECT_EQ(jc["kind"], "reference");
    EXPECT_EQ(jc["verdict"], "fail");
    EXPECT_TRUE(jc["checks"][0]["value"].is_number()); // the report's schema wants numbers
}

// The cost comparison: one judge_cost check per figure, the worst status, the messages joined; a
// figure the baseline did not approve is named (the caller stops the test with an error), not passed.
TEST(Verdict, CostsAreJudgedPerFigureAndAnUnapprovedFigureIsNamed) {
    const json approved = {{"spirv_instructions_per_pixel", 1000.0}, {"texture_fetches_per_pixel", 10.0}};
    CostJudgement ok =
        judge_costs({{"spirv_instructions_per_pixel", 1300.0}, {"texture_fetches_per_pixel", 5.0}}, approved, 0.25);
    EXPECT_TRUE(ok.unapproved.empty());
    EXPECT_EQ(ok.comparison.kind, "cost");
    ASSERT_EQ(ok.comparison.checks.size(), 2u);
    EXPECT_EQ(ok.comparison.checks[0].metric, "cost.spirv_instructions_per_pixel");
    EXPECT_EQ(ok.comparison.checks[0].status, Verdict::fail);
    EXPECT_EQ(ok.comparison.checks[1].status, Verdict::improved);
    EXPECT_EQ(ok.comparison.verdict, Verdict::fail);
    EXPECT_EQ(ok.comparison.message, ok.comparison.checks[0].message + "; " + ok.comparison.checks[1].message);
    EXPECT_EQ(judge_costs({{"texture_fetches_per_pixel", 10.0}}, approved, 0.25).comparison.verdict, Verdict::pass);
    for (const json& without : {json::object(), json{{"texture_fetches_per_pixel", "10"}}, json(3.0)}) {
        CostJudgement missing = judge_costs({{"texture_fetches_per_pixel", 10.0}}, without, 0.25);
        EXPECT_EQ(missing.unapproved, "texture_fetches_per_pixel") << without;
    }
}

// NaN/Inf in a render is the shader's fault (fail); anything else that stops a test is error.
TEST(Verdict, WhatStopsATestIsAFailOnlyForANonFiniteRender) {
    EXPECT_EQ(stop_verdict(TestStop::non_finite_render), Verdict::fail);
    EXPECT_EQ(stop_verdict(TestStop::shader_compile_error), Verdict::error);
    EXPECT_EQ(stop_verdict(TestStop::cannot_test), Verdict::error);
}

TEST(Verdict, StabilityFailsANonDeterministicRenderAndAFlakyOneOnlyWhenAsked) {
    EXPECT_EQ(stability_verdict(true, false, true), Verdict::pass);
    EXPECT_EQ(stability_verdict(false, false, false), Verdict::fail);
    EXPECT_EQ(stability_verdict(true, true, false), Verdict::pass);
    EXPECT_EQ(stability_verdict(true, true, true), Verdict::fail);
}

TEST(Verdict, TheTestMessageNamesThePlatformOnlyWhenTheTestDidNotPass) {
    const std::string diff = "golden blessed on another platform: CPU class a -> b";
    EXPECT_EQ(test_message({"baseline: x", "accuracy: y"}, Verdict::fail, diff), "baseline: x; accuracy: y; " + diff);
    EXPECT_EQ(test_message({}, Verdict::improved, diff), diff);
    EXPECT_EQ(test_message({}, Verdict::pass, diff), "");
    EXPECT_EQ(test_message({"flaky: z"}, Verdict::pass, std::nullopt), "flaky: z");
}

// run: 2 on any error, else 1 on fail or missing-golden; --repeat: a changed verdict makes 0 a 1;
// bisect: 0 good, 1 bad, 125 when a test could not be judged or has no golden.
TEST(Verdict, ExitCodesOfRunRepeatAndBisect) {
    auto counts = [](std::initializer_list<Verdict> vs) {
        VerdictCounts c;
        for (Verdict v : vs) c.add(v);
        return c;
    };
    const VerdictCounts pass = counts({Verdict::pass, Verdict::improved}), fail = counts({Verdict::pass, Verdict::fail}),
                        missing = counts({Verdict::missing_golden}), error = counts({Verdict::fail, Verdict::error});
    EXPECT_EQ(pass.pass, 1);
    EXPECT_EQ(pass.improved, 1);
    EXPECT_EQ(run_exit_code(pass), kExitPass);
    EXPECT_EQ(run_exit_code(fail), kExitRegression);
    EXPECT_EQ(run_exit_code(missing), kExitRegression);
    EXPECT_EQ(run_exit_code(error), kExitError);
    EXPECT_EQ(repeat_exit_code(kExitPass, 0), kExitPass);
    EXPECT_EQ(repeat_exit_code(kExitPass, 2), kExitRegression);
    EXPECT_EQ(repeat_exit_code(kExitError, 2), kExitError);
    EXPECT_EQ(bisect_exit_code(pass, false), kExitPass);
    EXPECT_EQ(bisect_exit_code(fail, false), kExitRegression);
    EXPECT_EQ(bisect_exit_code(missing, false), kExitCannotTest);
    EXPECT_EQ(bisect_exit_code(error, false), kExitCannotTest);
    EXPECT_EQ(bisect_exit_code(pass, true), kExitCannotTest);
    EXPECT_EQ(bisect_exit_code(fail, true), kExitCannotTest);
    EXPECT_EQ(bisect_verdict_name(kExitPass), "good");
    EXPECT_EQ(bisect_verdict_name(kExitRegression), "bad");
    EXPECT_EQ(bisect_verdict_name(kExitCannotTest), "skip (125)");
}

} // namespace test_verdict
