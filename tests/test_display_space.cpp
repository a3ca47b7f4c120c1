// Display space (issue 29): each step of what a player sees against values worked out by hand from
// the formats' and tonemappers' published definitions (never from this code), the suite's
// "display" block and its errors, and scoring in that space: LDR-FLIP, SSIM and PSNR after the
// display, which a change above white does not move and a change in the midtones does.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "harness/golden_comparisons.h"
#include "harness/golden_store.h"
#include "harness/suite.h"
#include "harness/verdict.h"
#include "kernel/errors.h"
#include "metrics/display_space.h"
#include "metrics/display_transform.h"
#include "metrics/image_compare.h"
#include "reports/report_html.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_display_space {

// IEEE binary16: 10 mantissa bits, largest 65504, subnormals down to 2^-24; ties to even.
TEST(DisplaySpace, HalfRoundingOfKnownValues) {
    EXPECT_EQ(round_to_half(1.0f), 1.0f);
    EXPECT_EQ(round_to_half(1.0f / 3.0f), 0.333251953125f); // 0x3555
    EXPECT_EQ(round_to_half(1.0f + 0x1p-11f), 1.0f);        // half an ulp above 1: tie, to even
    EXPECT_EQ(round_to_half(1.0f + 3 * 0x1p-11f), 1.0f + 0x1p-9f);
    EXPECT_EQ(round_to_half(65504.0f), 65504.0f);
    EXPECT_EQ(round_to_half(65519.0f), 65504.0f); // below the halfway point to 65536
    EXPECT_EQ(round_to_half(1e6f), 65504.0f);     // saturated, never inf
    EXPECT_EQ(round_to_half(0x1p-24f), 0x1p-24f); // the smallest subnormal
    EXPECT_EQ(round_to_half(0x1p-25f), 0.0f);     // half of it: tie, to even (0)
    EXPECT_EQ(round_to_half(3 * 0x1p-25f), 0x1p-23f);
    EXPECT_EQ(round_to_half(-2.5f), -2.5f); // signed
    EXPECT_TRUE(std::isnan(round_to_half(NAN)));
}

// Every finite value R11G11B10F can hold, decoded from its bits with the format's definition
// (Vulkan, "Unsigned 11-Bit/10-Bit Floating-Point Numbers"), comes back unchanged; values between
// two of them go to the nearer; no sign; the largest finite value is where it saturates.
TEST(DisplaySpace, R11G11B10RoundTripsAndRoundsKnownValues) {
    for (int bits : {6, 5}) {
        auto round = bits == 6 ? round_to_uf11 : round_to_uf10;
        const int m_count = 1 << bits;
        for (int e = 0; e < 31; ++e)
            for (int m = 0; m < m_count; ++m) {
                const double v = e == 0 ? std::ldexp(double(m) / m_count, -14) : std::ldexp(1.0 + double(m) / m_count, e - 15);
                ASSERT_EQ(round(float(v)), float(v)) << "bits " << bits << " e " << e << " m " << m;
            }
    }
    EXPECT_EQ(round_to_uf11(1.0f / 3.0f), 85.0f / 256.0f); // 1.010101|0101.. x 2^-2: rounds down
    EXPECT_EQ(round_to_uf10(1.0f / 3.0f), 43.0f / 128.0f); // 1.01010|10101.. x 2^-2: rounds up
    EXPECT_EQ(round_to_uf11(1.0f + 0x1p-7f), 1.0f);        // tie, to even
    EXPECT_EQ(round_to_uf11(1.0f + 3 * 0x1p-7f), 1.0f + 0x1p-5f);
    EXPECT_EQ(round_to_uf11(65024.0f), 65024.0f);
    EXPECT_EQ(round_to_uf11(1e5f), 65024.0f);
    EXPECT_EQ(round_to_uf10(1e5f), 64512.0f);
    EXPECT_EQ(round_to_uf11(-1.0f), 0.0f);
    EXPECT_EQ(round_to_uf11(0x1p-20f), 0x1p-20f); // the smallest subnormals: 2^-14 / 64, / 32
    EXPECT_EQ(round_to_uf10(0x1p-19f), 0x1p-19f);
    float r = 1.0f / 3.0f, g = 1.0f / 3.0f, b = 1.0f / 3.0f;
    round_to_target(RenderTarget::r11g11b10f, r, g, b);
    EXPECT_EQ(r, 85.0f / 256.0f);
    EXPECT_EQ(g, 85.0f / 256.0f);
    EXPECT_EQ(b, 43.0f / 128.0f);
}

TEST(DisplaySpace, SrgbOetfAndEightBitQuantisation) {
    EXPECT_EQ(std::lround(srgb_oetf(0.5f) * 255.0f), 188); // 187.516
    EXPECT_EQ(quantize_8bit(srgb_oetf(0.5f)), 188.0f / 255.0f);
    EXPECT_EQ(quantize_8bit(srgb_oetf(0.18f)), 118.0f / 255.0f); // 117.646: 18 % grey
    EXPECT_NEAR(srgb_oetf(0.18f), 0.4613561, 1e-6);
    EXPECT_NEAR(srgb_oetf(0.0031308f), 0.0404500, 1e-6); // the linear segment's end, 12.92 x
    EXPECT_EQ(srgb_oetf(-1.0f), 0.0f);
    EXPECT_FLOAT_EQ(srgb_oetf(2.0f), 1.0f);          // 1.055 − 0.055 in float
    EXPECT_EQ(quantize_8bit(0.5f), 128.0f / 255.0f); // 127.5: tie, to even
}

// Narkowicz: "1 on input maps to ~0.8 on output ... For the original ACES curve just multiply input
// by 0.6": with the 0.6, 1/0.6 maps to (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 0.80380.
TEST(DisplaySpace, AcesNarkowiczIsHisCurveWithTheOriginalScale) {
    EXPECT_NEAR(tonemap_aces_narkowicz(1.0f / 0.6f), 2.54 / 3.16, 1e-6);
    EXPECT_NEAR(tonemap_aces_narkowicz(1.0f), 0.9216 / 1.3688, 1e-6); // (.36·2.51 + .018) / (.36·2.43 + .354 + .14)
    EXPECT_EQ(tonemap_aces_narkowicz(0.0f), 0.0f);
    EXPECT_EQ(tonemap_aces_narkowicz(1e6f), 1.0f); // clamped
}

// Khronos PBR Neutral, from the specification's equations (values worked out by hand): base colours
// in [0.08, 0.8] come out as c − F90; below, the offset x − x²/(4 F90); above Ks = 0.76 the
// compression towards p_n = 1 − (1 − Ks)² / (p + 1 − 2 Ks) and the desaturation g.
TEST(DisplaySpace, PbrNeutralMatchesTheSpecification) {
    struct Case {
        float in[3], out[3];
    } cases[] = {
        {{0.5f, 0.3f, 0.1f}, {0.46f, 0.26f, 0.06f}},        // the spec's guarantee: c − 0.04
        {{0.8f, 0.8f, 0.8f}, {0.76f, 0.76f, 0.76f}},        // its upper end
        {{0.02f, 0.5f, 0.5f}, {0.0025f, 0.4825f, 0.4825f}}, // x = 0.02: f = 0.02 − 0.0004/0.16
        {{1, 1, 1}, {0.8690909f, 0.8690909f, 0.8690909f}},  // p = 0.96: p_n = 1 − 0.0576/0.44
        {{2, 1, 0.5f}, {0.96f, 0.5340905f, 0.3211358f}},    // p = 1.96: p_n = 0.96, g = 1/1.15
        {{10, 0, 0}, {0.9939241f, 0.5711416f, 0.5711416f}}, // p = 10, desaturated towards p_n
        {{0, 0, 0}, {0, 0, 0}},
    };
    for (const Case& c : cases) {
        float r = c.in[0], g = c.in[1], b = c.in[2];
        tonemap_pbr_neutral(r, g, b);
        EXPECT_NEAR(r, c.out[0], 2e-6) << c.in[0] << "," << c.in[1] << "," << c.in[2];
        EXPECT_NEAR(g, c.out[1], 2e-6);
        EXPECT_NEAR(b, c.out[2], 2e-6);
    }
    float r = INFINITY, g = 1e38f, b = 1e38f; // the brightest input is white, not NaN
    tonemap_pbr_neutral(r, g, b);
    EXPECT_NEAR(r, 1.0f, 1e-6);
    EXPECT_NEAR(b, 1.0f, 1e-6);
}

// The harness's linear SSIM/PSNR transform is this space with aces_narkowicz, 0 EV, no
// quantisation, rgba32f: the two cannot drift apart unnoticed.
TEST(DisplaySpace, TheLinearScoresTransformIsOneDisplaySpace) {
    cv::Mat img(4, 8, CV_32FC3);
    for (int i = 0; i < 32; ++i) img.at<cv::Vec3f>(i / 8, i % 8) = {0.01f * float(i * i), 0.3f * float(i), 1e-3f * float(i)};
    DisplaySpace d{DisplayTonemap::aces_narkowicz, 0.0, DisplayQuantize::none, RenderTarget::rgba32f};
    cv::Mat diff;
    cv::absdiff(to_display(img, d), display_transform(img), diff);
    EXPECT_EQ(cv::norm(diff, cv::NORM_INF), 0.0);
}

// Target, then exposure, then the tonemapper, the OETF and 8 bits: 1/3 in R11G11B10F is 85/256 (red,
// green) and 43/128 (blue); +1 EV gives 0.6640625 and 0.671875; PBR Neutral subtracts F90 = 0.04
// (min 0.664 > 0.08, peak 0.632 < Ks): 0.6240625 and 0.631875; the OETF 0.8118 and 0.8163; 8 bits
// 207 and 208 (207.015 and 208.164).
TEST(DisplaySpace, StepsComposeInOrder) {
    DisplaySpace d{DisplayTonemap::pbr_neutral, 1.0, DisplayQuantize::srgb8, RenderTarget::r11g11b10f};
    float r = 1.0f / 3.0f, g = 1.0f / 3.0f, b = 1.0f / 3.0f;
    to_display(d, r, g, b);
    EXPECT_EQ(r, 207.0f / 255.0f);
    EXPECT_EQ(g, 207.0f / 255.0f);
    EXPECT_EQ(b, 208.0f / 255.0f);
    EXPECT_EQ(display_label(d), "pbr_neutral_1ev_srgb8_r11g11b10f");
    EXPECT_EQ(display_json(d)["target"], "r11g11b10f");
    EXPECT_FALSE(parse_tonemap("aces_fitted")); // Hill's fit is not this curve: not accepted under its name
    EXPECT_EQ(parse_quantize("none"), DisplayQuantize::none);
}

namespace {

std::string load_error(const fs::path& file) {
    try {
        load_suite(file.string());
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

std::string one_test_suite(const std::string& test_fields) {
    return R"({"suite": "d", "tests": [{"scene": "sphere", "method": "mobile", )" + test_fields + "}]}";
}

// A horizontal ramp of grey radiance from 0.01 to 40 (log spaced): darks, midtones and highlights
// far beyond the tonemappers' white.
cv::Mat ramp() {
    cv::Mat m(32, 96, CV_32FC3);
    for (int y = 0; y < m.rows; ++y)
        for (int x = 0; x < m.cols; ++x) {
            const float v = 0.01f * std::pow(4000.0f, float(x) / float(m.cols - 1)) * (1.0f + 0.02f * float(y % 4));
            m.at<cv::Vec3f>(y, x) = {v, v * 0.9f, v * 0.8f};
        }
    return m;
}

// `m` with every channel of the pixels whose radiance lies in [lo, hi) multiplied by `gain`.
cv::Mat scaled(const cv::Mat& m, float lo, float hi, float gain) {
    cv::Mat out = m.clone();
    for (auto& p : cv::Mat_<cv::Vec3f>(out))
        if (p[0] >= lo && p[0] < hi) p *= gain;
    return out;
}

} // namespace

// Bad display config is an error (exit 2) naming the suite file and the field.
TEST(DisplaySuite, BadDisplayConfigNamesTheFileAndTheField) {
    const fs::path dir = temp_dir("display_schema");
    struct Case {
        std::string fields, expect;
    } cases[] = {
        {R"("display": {"tonemap": "aces_fitted"})", "tests[0].display.tonemap: unknown tonemapper 'aces_fitted'; valid: "},
        {R"("display": {"tonemap": "pbr_neutral", "exposure": "NaN"})", "tests[0].display.exposure: must be a number"},
        {R"("display": {"tonemap": "pbr_neutral", "exposure": 1e300})",
         "tests[0].display.exposure: must be a finite number of stops within"},
        {R"("display": {"tonemap": "pbr_neutral", "target": "rgb565"})",
         "tests[0].display.target: unknown render target 'rgb565'"},
        {R"("display": {"tonemap": "pbr_neutral", "quantize": "srgb10"})", "tests[0].display.quantize: unknown quantisation"},
        {R"("display": {"exposure": 0})", "tests[0].display.tonemap: missing required key"},
        {R"("display": {"tonemap": "pbr_neutral", "gamma": 2.2})", "tests[0].display.gamma: unknown key"},
        {R"("baseline_tolerances": {"display_flip.mean": {"max": 0.01}})",
         "tests[0].baseline_tolerances.display_flip.mean: mobile.sphere.studio.default has no \"display\""},
        {R"("display": null, "reference_band": {"display_ssim.mean": {"below": 0.1}})",
         "tests[0].reference_band.display_ssim.mean:"},
    };
    for (size_t i = 0; i < std::size(cases); ++i) {
        const fs::path f = dir / ("bad" + std::to_string(i) + ".json");
        write_file(f, one_test_suite(cases[i].fields));
        const std::string err = load_error(f);
        EXPECT_NE(err.find(f.string()), std::string::npos) << err;
        EXPECT_NE(err.find(cases[i].expect), std::string::npos) << err;
    }
    std::string out;
    const fs::path f = dir / "bad0.json";
    EXPECT_EQ(run_command(built("iblcheck") + " run -q --suite " + f.string() + " --out " + (dir / "out").string(), out), 2)
        << out;
    EXPECT_NE(out.find(f.string() + ": tests[0].display.tonemap: unknown tonemapper 'aces_fitted'"), std::string::npos) << out;
}

// The suite's display applies to every test; a test's own replaces it, null drops it; the name says
// the space, so a display test never shares a baseline with the linear test of the same render.
TEST(DisplaySuite, DefaultsApplyTestsOverrideOrDropAndNamesSayTheSpace) {
    const fs::path f = temp_dir("display_names") / "d.json";
    write_file(f, R"({"suite": "d", "defaults": {"display": {"tonemap": "aces_narkowicz"}},
      "tests": [{"scene": "sphere", "method": "mobile", "baseline_tolerances": {"display_flip.mean": {"max": 0.01}}},
                {"scene": "sphere", "method": "mobile", "baseline_tolerances": {"flip.mean": {"max": 0.01}},
                 "display": {"tonemap": "pbr_neutral", "exposure": -1.5, "quantize": "none", "target": "rgba16f"}},
                {"scene": "sphere", "method": "mobile", "baseline_tolerances": {"flip.mean": {"max": 0.01}}, "display": null}]})");
    const Suite s = load_suite(f.string());
    ASSERT_EQ(s.tests.size(), 3u);
    EXPECT_EQ(s.tests[0].name, "mobile.sphere.studio.default.display=aces_narkowicz_0ev_srgb8_rgba32f");
    EXPECT_EQ(s.tests[1].name, "mobile.sphere.studio.default.display=pbr_neutral_-1.5ev_none_rgba16f");
    ASSERT_TRUE(s.tests[1].display);
    EXPECT_EQ(s.tests[1].display->exposure_ev, -1.5);
    EXPECT_EQ(s.tests[1].display->target, RenderTarget::rgba16f);
    EXPECT_EQ(s.tests[2].name, "mobile.sphere.studio.default");
    EXPECT_FALSE(s.tests[2].display);
}

// A change above the tonemapper's white (radiance 16 -> 32, past ACES's 1.0 at 12.1) is invisible on
// the display: LDR-FLIP 0, PSNR "identical"; linear HDR-FLIP, which looks at 2^-k exposures, fails
// it. A 5 % change of the midtones is seen in both spaces.
TEST(DisplayScores, AboveWhiteIsInvisibleOnTheDisplayMidtonesAreNot) {
    const DisplaySpace d{DisplayTonemap::aces_narkowicz, 0.0, DisplayQuantize::srgb8, RenderTarget::rgba16f};
    const cv::Mat ref = ramp();
    const nlohmann::json hi = compare_images(ref, scaled(ref, 16.0f, 1e9f, 2.0f), 1, nullptr, &d);
    EXPECT_EQ(hi["display"]["tonemap"], "aces_narkowicz");
    EXPECT_EQ(hi["display_flip"]["mode"], "ldr");
    EXPECT_EQ(hi["display_flip"]["mean"].get<double>(), 0.0);
    EXPECT_EQ(hi["display_psnr"]["db"].get<double>(), 999.0);
    EXPECT_GT(hi["flip"]["mean"].get<double>(), 0.01);
    const std::map<std::string, Bound> display_only = {{"display_flip.mean", Bound{std::nullopt, 0.001}}};
    const std::map<std::string, Bound> linear = {{"flip.mean", Bound{std::nullopt, 0.001}}};
    EXPECT_EQ(judge_baseline(hi, display_only).verdict, Verdict::pass);
    EXPECT_EQ(judge_baseline(hi, linear).verdict, Verdict::fail);

    const nlohmann::json mid = compare_images(ref, scaled(ref, 0.1f, 0.5f, 1.05f), 1, nullptr, &d);
    EXPECT_GT(mid["display_flip"]["mean"].get<double>(), 0.001);
    EXPECT_LT(mid["display_ssim"]["mean"].get<double>(), 1.0);
    EXPECT_EQ(judge_baseline(mid, display_only).verdict, Verdict::fail);
    EXPECT_FALSE(compare_images(ref, ref, 1).contains("display_flip")); // no display: linear figures only
}

// Display SSIM and PSNR are better when higher, like their linear twins: a drop of the display SSIM
// against the truth is a failure, not an improvement.
TEST(DisplayScores, DisplaySsimAndPsnrAreHigherIsBetter) {
    EXPECT_TRUE(higher_is_better("display_ssim.mean"));
    EXPECT_TRUE(higher_is_better("accuracy.display_psnr.db"));
    EXPECT_FALSE(higher_is_better("accuracy.display_flip.mean"));
    EXPECT_EQ(judge_band("accuracy.display_ssim.mean", 0.70, 0.86, Band{}).status, Verdict::fail);
    EXPECT_EQ(judge_band("accuracy.display_flip.mean", 0.15, 0.19, Band{}).status, Verdict::improved);
}

// The ci suite's display tests against their blessed baselines and their own tolerances: the
// baseline passes; the render 4 % brighter (+0.057 EV: a shift a player sees when the two frames
// alternate; display_flip.mean 0.050 and 0.031, 30-50x the bound) fails; the pixels already at the
// display's white, doubled, pass (sky_sun under ACES: 2273 of 50688 pixels; PBR Neutral's white is
// asymptotic, the studio render has none), where the linear tolerances of the other ci tests fail
// them (HDR-FLIP p99 0.58, worst block 0.21).
TEST(DisplayScores, CiDisplayTestsFailAChangeVisibleOnTheDisplay) {
    const Suite ci = load_suite("ci");
    const GoldenStore store;
    const std::map<std::string, Bound> linear = ci.tests.front().baseline_tolerances; // the linear gate
    ASSERT_FALSE(ci.tests.front().display);
    int display_tests = 0;
    size_t white_pixels = 0;
    for (const TestCase& tc : ci.tests) {
        if (!tc.display) continue;
        ++display_tests;
        const std::vector<Golden> goldens = store.baselines(tc.name);
        ASSERT_EQ(goldens.size(), 1u) << tc.name << ": bless it with iblcheck bless --suite ci --filter '*display=*'";
        const cv::Mat& g = goldens[0].image;
        auto judge = [&](const cv::Mat& img, const std::map<std::string, Bound>& tol) {
            return judge_baseline(compare_images(g, img, 1, nullptr, &*tc.display), tol);
        };
        EXPECT_EQ(judge(g, tc.baseline_tolerances).verdict, Verdict::pass) << tc.name;
        const Comparison brighter = judge(g * 1.04, tc.baseline_tolerances);
        EXPECT_EQ(brighter.verdict, Verdict::fail) << tc.name;
        EXPECT_NE(brighter.message.find("display_flip.mean"), std::string::npos) << brighter.message;
        cv::Mat hi = g.clone();
        const cv::Mat shown = to_display(g, *tc.display);
        size_t white = 0;
        for (int y = 0; y < g.rows; ++y)
            for (int x = 0; x < g.cols; ++x)
                if (shown.at<cv::Vec3f>(y, x) == cv::Vec3f(1, 1, 1)) {
                    hi.at<cv::Vec3f>(y, x) *= 2.0f;
                    ++white;
                }
        EXPECT_EQ(judge(hi, tc.baseline_tolerances).verdict, Verdict::pass) << tc.name;
        if (white) {
            EXPECT_EQ(judge(hi, linear).verdict, Verdict::fail) << tc.name;
        }
        white_pixels += white;
    }
    EXPECT_EQ(display_tests, 2);
    EXPECT_GT(white_pixels, 1000u); // the highlight check changed something
}

// A display test's failure is located where its tolerances looked: the worst block and the heatmap
// of its baseline comparison come from the LDR-FLIP map on the display, and say so.
TEST(DisplayScores, ADisplayTestsWorstBlockIsFoundOnTheDisplay) {
    const Suite ci = load_suite("ci");
    const GoldenStore store;
    for (const TestCase& tc : ci.tests) {
        if (!tc.display) continue;
        RenderResult rr;
        rr.image = store.baselines(tc.name).at(0).image * 1.04;
        rr.coverage.ids = cv::Mat(rr.image.size(), CV_32S, cv::Scalar(-1));
        const BaselineOutcome b = judge_against_baselines(tc, rr, store, Artefacts{}, 1);
        ASSERT_EQ(b.comparison.verdict, Verdict::fail) << tc.name;
        ASSERT_TRUE(b.comparison.worst_block.has_value());
        EXPECT_EQ(b.comparison.worst_block->metric, "display_flip");
        EXPECT_EQ(b.comparison.worst_block->flip, b.comparison.metrics["display_flip"]["block_max"].get<double>());
        EXPECT_NE(b.comparison.worst_block->flip, b.comparison.metrics["flip"]["block_max"].get<double>());
        EXPECT_NE(b.comparison.message.find("with mean LDR-FLIP on the display"), std::string::npos) << b.comparison.message;
    }
}

// The nightly's chart: one panel per scene, environment and space, a point per test at (linear
// HDR-FLIP, display LDR-FLIP) vs the truth, and the measured change of the ranking under it.
TEST(DisplayChart, PanelsPlotLinearAgainstDisplayAndStateTheRankChange) {
    using report::html::spearman_rho;
    EXPECT_DOUBLE_EQ(spearman_rho({0.1, 0.2, 0.3}, {1, 5, 9}), 1.0);
    EXPECT_DOUBLE_EQ(spearman_rho({0.1, 0.2, 0.3}, {9, 5, 1}), -1.0);
    EXPECT_NEAR(spearman_rho({1, 2, 3, 4}, {1, 3, 2, 4}), 0.8, 1e-12); // 1 − 6·2/(4·15)
    EXPECT_TRUE(std::isnan(spearman_rho({1, 2}, {3, 3})));
    const nlohmann::json space = {{"tonemap", "pbr_neutral"}, {"exposure", 0}, {"quantize", "srgb8"}, {"target", "rgba16f"}};
    std::vector<nlohmann::json> tests;
    const double lin[] = {0.1, 0.2, 0.3, 0.4, 0.5}, dis[] = {0.05, 0.04, 0.03, 0.02, 0.06};
    for (int i = 0; i < 5; ++i)
        tests.push_back({{"name", "mobile.roughness_sweep.studio.v" + std::to_string(i)},
                         {"method", "mobile"},
                         {"scene", "roughness_sweep"},
                         {"env", "studio"},
                         {"variant", "v" + std::to_string(i)},
                         {"accuracy", {{"flip_mean", lin[i]}, {"display", {{"space", space}, {"flip_mean", dis[i]}}}}}});
    tests.push_back({{"name", "linear.only"}, {"method", "mobile"}, {"accuracy", {{"flip_mean", 0.1}}}});
    std::vector<const nlohmann::json*> ptrs;
    for (const auto& t : tests) ptrs.push_back(&t);
    const std::string html = report::html::display_section(ptrs);
    EXPECT_NE(html.find("data-chart=\"linear-display-roughness-sweep-studio-pbr-neutral-0-EV-srgb8-rgba16f\" data-points=\"5\""),
              std::string::npos)
        << html.substr(0, 2000);
    // Ranks by linear 1..5; by display 4, 3, 2, 1, 5: ρ = 1 − 6·(9+1+1+9+0)/(5·24) = 0.
    EXPECT_NE(html.find("Spearman \u03c1 = 0.00 over 5 tests; 2 move 3 or more places; largest: mobile v0 (linear #1 "
                        "\u2192 display #4), mobile v3 (linear #4 \u2192 display #1)"),
              std::string::npos)
        << html.substr(0, 3000);
    EXPECT_EQ(report::html::display_section({ptrs.back()}), ""); // nothing scored in a display space: no section
    const std::string one = report::html::display_section({ptrs.front()});
    EXPECT_NE(one.find("No scene, environment and space has two tests scored in it."), std::string::npos) << one;
    EXPECT_EQ(one.find("data-chart="), std::string::npos) << one;
}
} // namespace test_display_space
