// `iblcheck explain`'s ladder (harness/error_budget.h): its plan, its bookkeeping, and the split-sum
// rungs of the quadrature truth against independent figures in the white furnace.
#include "harness/error_budget.h"

#include <gtest/gtest.h>

#include <cmath>

#include "kernel/errors.h"
#include "renderers/environments/environment.h"
#include "renderers/reference/quadrature/split_sum.h"
#include "renderers/reference/quadrature/truth_renderer.h"
#include "renderers/scenes/coverage.h"
#include "renderers/scenes/scene.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_error_budget {

namespace {
std::vector<std::string> keys(const std::vector<BudgetRung>& rungs) {
    std::vector<std::string> k;
    for (const auto& r : rungs) k.push_back(r.key);
    return k;
}
OptionMap options(std::initializer_list<std::pair<const char*, const char*>> kv) {
    OptionMap o;
    for (auto& [k, v] : kv) o.set(k, v);
    return o;
}
} // namespace

TEST(ErrorBudget, DefaultConfigurationWalksTheStepsItUses) {
    const BudgetPlan p = plan_budget("roughness_sweep", "studio", OptionMap());
    EXPECT_EQ(keys(p.ladder), (std::vector<std::string>{"split_sum", "env_brdf_approx", "mip_chain", "ssaa", "prefilter_samples",
                                                        "diffuse", "storage"}));
    EXPECT_EQ(keys(p.isolated), (std::vector<std::string>{"ssaa", "prefilter_samples", "diffuse", "storage"}));
    EXPECT_EQ(p.truth.method, "reference");
    EXPECT_EQ(p.ladder[0].spec.options.get_string("split_sum"), "exact");
    // The converged state, and the last rung is the configuration's values (the option table's defaults).
    const OptionMap& c = p.ladder[2].spec.options;
    EXPECT_EQ(c.get_string("prefilter_samples"), "4096");
    EXPECT_EQ(c.get_string("diffuse"), "irradiance_cube");
    const OptionMap& last = p.ladder.back().spec.options;
    EXPECT_EQ(last.get_string("ssaa"), "2");
    EXPECT_EQ(last.get_string("prefilter_samples"), "256");
    EXPECT_EQ(last.get_string("diffuse"), "sh9");
    EXPECT_EQ(last.get_string("storage"), "rgba16f");
    // An isolated step changes only its own option from the converged state.
    EXPECT_EQ(p.isolated[2].spec.options.get_string("diffuse"), "sh9");
    EXPECT_EQ(p.isolated[2].spec.options.get_string("prefilter_samples"), "4096");
}

TEST(ErrorBudget, ConfigurationOptionsAddStepsAndHeldOptionsPassThrough) {
    const BudgetPlan p = plan_budget("roughness_sweep", "studio",
                                     options({{"precision", "mediump"},
                                              {"normalization", "ue4"},
                                              {"cube_size", "64"},
                                              {"prefilter_samples", "4096"},
                                              {"truth_tolerance", "0.004"}}));
    EXPECT_EQ(keys(p.ladder), (std::vector<std::string>{"split_sum", "env_brdf_approx", "mip_chain", "ssaa", "diffuse", "storage",
                                                        "precision", "normalization"}));
    EXPECT_EQ(p.ladder[2].spec.options.get_string("cube_size"), "64"); // held from the converged rung on
    EXPECT_FALSE(p.ladder[2].spec.options.has("truth_tolerance"));     // a truth control: CPU rungs only
    EXPECT_EQ(p.ladder[0].spec.options.get_string("truth_tolerance"), "0.004");
}

TEST(ErrorBudget, OrderPutsTheNamedStepsFirst) {
    const BudgetPlan p = plan_budget("roughness_sweep", "studio", OptionMap(), {"storage", "prefilter_samples"});
    EXPECT_EQ(keys(p.ladder), (std::vector<std::string>{"split_sum", "env_brdf_approx", "mip_chain", "storage",
                                                        "prefilter_samples", "ssaa", "diffuse"}));
    EXPECT_THROW(plan_budget("roughness_sweep", "studio", OptionMap(), {"cube_size"}), UsageError);
}

TEST(ErrorBudget, RefusesWhatTheTruthDoesNotModel) {
    try {
        plan_budget("roughness_sweep", "studio", options({{"ao", "0.5"}}));
        FAIL() << "ao accepted";
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("ao=0.5"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(plan_budget("roughness_sweep", "studio", options({{"ao", "1"}})));
    EXPECT_THROW(plan_budget("roughness_sweep", "studio", options({{"samples", "64"}})), UsageError); // sampled only
    EXPECT_THROW(plan_budget("roughness_sweep", "studio", options({{"split_sum", "exact"}})), UsageError);
    EXPECT_THROW(plan_budget("roughness_sweep", "studio", options({{"no_such_option", "1"}})), UsageError);
}

TEST(ErrorBudget, SharesTelescopeAndIsolatedPlusInteractionIsTheTotal) {
    const BudgetPlan p = plan_budget("roughness_sweep", "studio", options({{"diffuse", "irradiance_cube"}}));
    ASSERT_EQ(keys(p.isolated), (std::vector<std::string>{"ssaa", "prefilter_samples", "storage"}));
    SphereCoverage cov;
    cov.spheres = {{"a", 0.5f, 1}, {"b", 1, 0}};
    auto e = [](double f0, double f1) { return RungErrors{{f0 + f1, 0.1 * f0, f0}, {{f0, 0, f0}, {f1, 0, f1}}}; };
    const std::vector<RungErrors> ladder = {e(0.02, 0.01), e(0.05, 0.02), e(0.08, 0.06),
                                            e(0.09, 0.07), e(0.12, 0.07), e(0.10, 0.09)};
    const std::vector<RungErrors> isolated = {e(0.085, 0.065), e(0.11, 0.062), e(0.081, 0.08)};
    const std::vector<RungErrors> steps = {e(0.02, 0.01), e(0.03, 0.01), e(0.04, 0.05),
                                           e(0.01, 0.01), e(0.05, 0.0),  e(0.06, 0.03)};
    const nlohmann::json b = budget_json(p, ladder, isolated, cov, steps);
    EXPECT_NEAR(b["rungs"][2]["step"]["spheres"][1]["flip"].get<double>(), 0.05, 1e-12); // as measured, not a difference
    ASSERT_EQ(b["rungs"].size(), 6u);
    EXPECT_NEAR(b["rungs"][4]["share"]["spheres"][0]["flip"].get<double>(), 0.03, 1e-12);
    EXPECT_NEAR(b["rungs"][4]["isolated"]["spheres"][0]["flip"].get<double>(), 0.11 - 0.08, 1e-12);
    EXPECT_NEAR(b["rungs"][1]["isolated"]["spheres"][1]["flip"].get<double>(), 0.01, 1e-12); // base rung: its share
    for (int s = 0; s < 2; ++s) {
        const double total = b["total"]["spheres"][s]["flip"].get<double>();
        EXPECT_NEAR(b["sum_of_shares"]["spheres"][s]["flip"].get<double>(), total, 1e-12);
        EXPECT_NEAR(b["sum_of_isolated"]["spheres"][s]["flip"].get<double>() +
                        b["interaction"]["spheres"][s]["flip"].get<double>(),
                    total, 1e-12);
    }
    // sphere a: Σ isolated = 0.08 (base) + 0.005 + 0.03 + 0.001; interaction = 0.10 − 0.116.
    EXPECT_NEAR(b["interaction"]["spheres"][0]["flip"].get<double>(), 0.10 - 0.116, 1e-12);
    EXPECT_NE(budget_table(b).find("storage rgba32f -> rgba16f"), std::string::npos) << budget_table(b);
}

// The white furnace (F0 = 1, L = 1): the prefiltered radiance is 1 whatever α, so the split sum with
// exact parts equals the truth (E(n·v, α) = A + B), and the EnvBRDFApprox rung differs from it by
// (A + B)_approx − (A + B)_exact: at a sphere's centre (n·v = 1) 0.450 against 0.307 at r = 1.
TEST(ErrorBudget, SplitSumRungsInTheWhiteFurnaceHaveTheirIndependentFigures) {
    const Environment env = load_environment("constant:1");
    TestSpec spec;
    spec.scene = "furnace", spec.method = "reference", spec.env = "constant:1";
    spec.options.set("truth_tolerance", "0.004");
    spec.options.set("threads", "2");
    const cv::Mat truth = truth::render_truth(spec, env).result.image;
    spec.options.set("split_sum", "exact");
    const cv::Mat exact = truth::render_truth(spec, env).result.image;
    spec.options.set("split_sum", "env_brdf_approx");
    const cv::Mat approx = truth::render_truth(spec, env).result.image;
    const Scene scene = build_scene("furnace", {});
    const SphereCoverage cov = sphere_coverage(scene, truth.cols, truth.rows);
    const RungErrors e_exact = measure_errors(truth, exact, cov, 0), e_approx = measure_errors(truth, approx, cov, 0);
    ASSERT_EQ(e_exact.spheres.size(), 5u);
    // Per sphere: the bias (A + B)_approx/(A + B)_exact − 1 over the sphere's pixels, each pixel the
    // mean over 16x16 points of its footprint inside the disc (the truth integrates the footprint).
    for (size_t s = 0; s < 5; ++s) {
        const double r = scene.spheres[s].material.roughness, alpha = r * r;
        double sum_exact = 0, sum_approx = 0;
        for (int y = 0; y < truth.rows; ++y)
            for (int x = 0; x < truth.cols; ++x) {
                if (cov.ids.at<int>(y, x) != int(s)) continue;
                for (int k = 0; k < 256; ++k) {
                    const double px = x + (k % 16 + 0.5) / 16, py = y + (k / 16 + 0.5) / 16;
                    const double wx = (2 * px / truth.cols - 1) * 2.5 - scene.spheres[s].center.x;
                    const double wy = (1 - 2 * py / truth.rows) * 0.5;
                    const double rho2 = (wx * wx + wy * wy) / (0.45 * 0.45);
                    if (rho2 >= 1) continue;
                    const double nv = std::sqrt(1 - rho2);
                    const truth::Dfg ge = truth::dfg_exact_cached(nv, alpha), ga = truth::env_brdf_approx(r, nv);
                    sum_exact += ge.a + ge.b, sum_approx += ga.a + ga.b;
                }
            }
        SCOPED_TRACE(testing::Message() << "r = " << r);
        EXPECT_LT(std::fabs(e_exact.spheres[s].bias), 2e-3); // n = v = R costs nothing under constant light
        EXPECT_NEAR(e_approx.spheres[s].bias, sum_approx / sum_exact - 1, 5e-3);
    }
    // The r = 1 sphere's centre pixel (n·v > 0.999): the exact rung 1 − ln 2, EnvBRDFApprox 0.450.
    const int cx = 4 * 64 + 32, cy = 32;
    EXPECT_NEAR(exact.at<cv::Vec3f>(cy, cx)[1], 0.30685, 2e-3);
    EXPECT_NEAR(approx.at<cv::Vec3f>(cy, cx)[1], 0.4500, 2e-3);
}
} // namespace test_error_budget
