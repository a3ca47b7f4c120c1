// FLIP agreement with NVIDIA's reference tool (NVlabs/flip v1.6) on the shared test vectors
// (IBLCHECK_SHARED_DIR/flip-vectors, described by its expected.json), plus the heatmap and
// threading determinism. `iblcheck compare` on good and bad input: test_compare_command.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/display_transform.h"
#include "metrics/flip.h"
#include "metrics/flip/kernels.h"
#include "metrics/flip/magma_table.h"
#include "metrics/flip_json.h"
#include "tests/synthetic_image.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using iblcheck::testing_support::synthetic;

// Its own namespace: the test programs of one group compile as one unity unit (tests/CMakeLists.txt).
namespace test_metrics_flip {

namespace {

const fs::path kVectors = fs::path(IBLCHECK_SHARED_DIR) / "flip-vectors";

#define REQUIRE_VECTORS()                                                                                                        \
    if (!fs::exists(kVectors / "expected.json"))                                                                                 \
    GTEST_SKIP() << kVectors.string() << " not found: the FLIP test vectors (expected.json, "                                    \
                 << "image pairs, reference error maps) live in the shared folder beside the checkout"

nlohmann::json expected() {
    std::ifstream f(kVectors / "expected.json");
    return nlohmann::json::parse(f);
}

nlohmann::json pair_named(const std::string& name) {
    static const nlohmann::json all = expected();
    for (const auto& p : all["pairs"])
        if (p["name"] == name) return p;
    throw std::runtime_error("no pair " + name);
}

// Cache: the 1080p pairs are used by several tests.
const FlipResult& flip_for(const std::string& name) {
    static std::map<std::string, FlipResult> cache;
    auto it = cache.find(name);
    if (it != cache.end()) return it->second;
    const auto p = pair_named(name);
    const auto ref = read_image((kVectors / p["reference"].get<std::string>()).string());
    const auto test = read_image((kVectors / p["test"].get<std::string>()).string());
    FlipResult r = p["mode"] == "hdr" ? compute_flip_hdr(ref.pixels, test.pixels) : compute_flip_ldr(ref.pixels, test.pixels);
    return cache.emplace(name, std::move(r)).first->second;
}

class FlipVectors : public ::testing::TestWithParam<std::string> {};

TEST_P(FlipVectors, AgreesWithReferenceTool) {
    REQUIRE_VECTORS();
    const auto p = pair_named(GetParam());
    const FlipResult& r = flip_for(GetParam());
    ASSERT_EQ(r.errmap.cols, p["width"].get<int>());
    ASSERT_EQ(r.errmap.rows, p["height"].get<int>());
    EXPECT_EQ(r.mode, p["mode"].get<std::string>());

    // Per-pixel agreement with the tool's error map.
    const auto ref_map = read_image((kVectors / p["errmap"].get<std::string>()).string());
    double max_delta = 0.0;
    int mx = 0, my = 0;
    for (int y = 0; y < r.errmap.rows; ++y) {
        const float* a = r.errmap.ptr<float>(y);
        const float* b = ref_map.pixels.ptr<float>(y);
        for (int x = 0; x < r.errmap.cols; ++x) {
            const double d = std::fabs(double(a[x]) - double(b[3 * x]));
            if (d > max_delta) max_delta = d, mx = x, my = y;
        }
    }
    std::cout << "[ " << GetParam() << " ] max per-pixel |delta| = " << max_delta << " at (" << mx << ", " << my << "); mean "
              << r.mean << " vs " << p["mean_double"].get<double>() << " (delta " << r.mean - p["mean_double"].get<double>()
              << ")\n";
    EXPECT_LE(max_delta, 2e-4) << "at x=" << mx << ", y=" << my;

    EXPECT_NEAR(r.mean, p["mean_double"].get<double>(), 1e-5);
    EXPECT_NEAR(r.weighted_median, p["weighted_median"].get<double>(), 1e-4);
    EXPECT_NEAR(r.weighted_q1, p["weighted_q1"].get<double>(), 1e-4);
    EXPECT_NEAR(r.weighted_q3, p["weighted_q3"].get<double>(), 1e-4);
    EXPECT_NEAR(r.min, p["min"].get<double>(), 1e-4);
    EXPECT_NEAR(r.max, p["max"].get<double>(), 2e-4);
    EXPECT_NEAR(r.ppd, 67.0206451, 1e-5);
    if (p["mode"] == "hdr") {
        EXPECT_NEAR(r.start_exposure, p["start_exposure"].get<double>(), 1e-4);
        EXPECT_NEAR(r.stop_exposure, p["stop_exposure"].get<double>(), 1e-4);
        EXPECT_EQ(r.num_exposures, p["num_exposures"].get<int>());
    }
    // Sanity of the extra statistics.
    EXPECT_GE(r.p99, r.weighted_median * 0.5);
    EXPECT_LE(r.p99, r.max);
    EXPECT_GE(r.block_max, r.mean);
    EXPECT_LE(r.block_max, r.max);
}

INSTANTIATE_TEST_SUITE_P(AllPairs, FlipVectors, ::testing::Values("gen512_ldr", "gen512_hdr", "ref1080_ldr", "ramp1080_hdr"));

TEST(Flip, IdenticalImagesGiveZeroError) {
    const cv::Mat a = synthetic(64, 48, 1, 0.05f);
    const FlipResult r = compute_flip_ldr(a, a);
    EXPECT_EQ(r.max, 0.0);
    EXPECT_EQ(r.mean, 0.0);
    const FlipResult h = compute_flip_hdr(a * 4.0, a * 4.0);
    EXPECT_EQ(h.max, 0.0);
}

// Issue 33: bit-identical inputs skip HDR-FLIP's exposures. The skipped evaluation gives the same
// bits: on committed goldens (the ci suite's usual pass: a render equal to its baseline) and on
// synthetic HDR with a 1e4 highlight, every statistic, the exposures and the error map match the
// evaluated result exactly.
TEST(Flip, IdenticalHdrInputsSkipTheExposuresWithTheSameResult) {
    std::vector<cv::Mat> images;
    for (const char* g :
         {"goldens/baseline/mobile.roughness_sweep.sky_sun.default.exr", "goldens/reference/furnace__constant-1.exr"})
        images.push_back(read_image(std::string(IBLCHECK_SOURCE_DIR) + "/" + g).pixels);
    cv::Mat hdr = synthetic(97, 61, 3, 0.1f) * 8.0;
    hdr.at<cv::Vec3f>(10, 20) = cv::Vec3f(1e4f, 9e3f, 8e3f);
    images.push_back(hdr);
    for (const cv::Mat& img : images) {
        ASSERT_FALSE(img.empty());
        FlipOptions evaluated;
        evaluated.skip_identical = false;
        const FlipResult a = compute_flip_hdr(img, img.clone()), b = compute_flip_hdr(img, img.clone(), evaluated);
        EXPECT_EQ(flip_json(a).dump(), flip_json(b).dump());
        ASSERT_EQ(a.errmap.size(), b.errmap.size());
        EXPECT_EQ(std::memcmp(a.errmap.data, b.errmap.data, a.errmap.total() * sizeof(float)), 0);
        EXPECT_EQ(b.max, 0.0); // what the skip assumes: identical inputs score 0 at every pixel
    }
}

TEST(Flip, ErrorGrowsWithDistortion) {
    const cv::Mat a = synthetic(96, 64, 2, 0.0f);
    const cv::Mat b1 = a + cv::Scalar(0.02, 0.02, 0.02), b2 = a + cv::Scalar(0.2, 0.0, 0.0);
    const double e1 = compute_flip_ldr(a, b1).mean, e2 = compute_flip_ldr(a, b2).mean;
    EXPECT_GT(e1, 0.0);
    EXPECT_GT(e2, e1 * 2);
}

TEST(Flip, ThreadCountDoesNotChangeResults) {
    const cv::Mat a = synthetic(173, 97, 3, 0.1f), b = synthetic(173, 97, 4, 0.1f);
    FlipOptions o1, o2, o3;
    o1.threads = 1, o2.threads = 2, o3.threads = 5;
    const FlipResult r1 = compute_flip_hdr(a * 3.0, b * 3.0, o1);
    const FlipResult r2 = compute_flip_hdr(a * 3.0, b * 3.0, o2);
    const FlipResult r3 = compute_flip_hdr(a * 3.0, b * 3.0, o3);
    EXPECT_EQ(cv::norm(r1.errmap, r2.errmap, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(r1.errmap, r3.errmap, cv::NORM_INF), 0.0);
    EXPECT_EQ(r1.mean, r2.mean);
    EXPECT_EQ(r1.weighted_median, r3.weighted_median);
    const FlipResult l1 = compute_flip_ldr(a, b, o1), l2 = compute_flip_ldr(a, b, o2);
    EXPECT_EQ(cv::norm(l1.errmap, l2.errmap, cv::NORM_INF), 0.0);
}

TEST(Flip, ThreadCountBitIdenticalOn1080p) {
    REQUIRE_VECTORS();
    const auto ref = read_image((kVectors / "reference.png").string());
    const auto test = read_image((kVectors / "reference_degraded.png").string());
    FlipOptions o1, o2;
    o1.threads = 1, o2.threads = 2;
    const FlipResult r1 = compute_flip_ldr(ref.pixels, test.pixels, o1);
    const FlipResult r2 = compute_flip_ldr(ref.pixels, test.pixels, o2);
    EXPECT_EQ(cv::norm(r1.errmap, r2.errmap, cv::NORM_INF), 0.0);
    EXPECT_EQ(r1.mean, r2.mean);
}

TEST(Flip, ExplicitExposuresAreUsed) {
    const cv::Mat a = synthetic(64, 64, 5, 0.05f) * 2.0, b = synthetic(64, 64, 6, 0.05f) * 2.0;
    FlipOptions o;
    o.start_exposure = -1.0f;
    o.stop_exposure = 2.0f;
    const FlipResult r = compute_flip_hdr(a, b, o);
    EXPECT_EQ(r.start_exposure, -1.0);
    EXPECT_EQ(r.stop_exposure, 2.0);
    EXPECT_EQ(r.num_exposures, 3);
    o.stop_exposure = -2.0f;
    EXPECT_THROW(compute_flip_hdr(a, b, o), UsageError);
}

TEST(Flip, SizeMismatchThrows) { EXPECT_THROW(compute_flip_ldr(synthetic(32, 32, 1, 0), synthetic(33, 32, 1, 0)), InputError); }

TEST(Flip, BlockMaxFindsTheWorstBlock) {
    FlipResult r;
    r.errmap = cv::Mat::zeros(40, 50, CV_32F);
    r.errmap(cv::Rect(32, 16, 16, 16)).setTo(0.5f);
    r.errmap.at<float>(0, 0) = 1.0f; // a single hot pixel does not beat a whole bad block
    pool_flip_errmap(r);
    EXPECT_EQ(r.block_x, 32);
    EXPECT_EQ(r.block_y, 16);
    EXPECT_DOUBLE_EQ(r.block_max, 0.5);
    EXPECT_EQ(r.max, 1.0);
    EXPECT_NEAR(r.mean, (256 * 0.5 + 1.0) / 2000.0, 1e-12);
}

// results.json and `iblcheck compare --json` write FLIP through flip_json: the statistics by value,
// and the exposure keys only for HDR results.
TEST(Flip, JsonHoldsTheStatisticsAndHdrExposures) {
    const cv::Mat a = synthetic(64, 48, 7, 0.05f), b = synthetic(64, 48, 8, 0.05f);
    const FlipResult l = compute_flip_ldr(a, b);
    const nlohmann::json lj = flip_json(l);
    EXPECT_EQ(lj.size(), 11u);
    EXPECT_EQ(lj["mean"].get<double>(), l.mean);
    EXPECT_EQ(lj["weighted_q3"].get<double>(), l.weighted_q3);
    EXPECT_EQ(lj["block_x"].get<int>(), l.block_x);
    EXPECT_EQ(lj["mode"], "ldr");
    EXPECT_FALSE(lj.contains("start_exposure"));
    EXPECT_FALSE(lj.contains("errmap"));
    const FlipResult h = compute_flip_hdr(a * 3.0, b * 3.0);
    const nlohmann::json hj = flip_json(h);
    EXPECT_EQ(hj.size(), 15u);
    EXPECT_EQ(hj["mode"], "hdr");
    EXPECT_EQ(hj["stop_exposure"].get<double>(), h.stop_exposure);
    EXPECT_EQ(hj["num_exposures"].get<int>(), h.num_exposures);
    EXPECT_EQ(hj["exposure_source"], h.exposure_source);
}

TEST(Flip, MagmaHeatmapMatchesTable) {
    cv::Mat e(1, 4, CV_32F);
    e.at<float>(0, 0) = 0.0f;
    e.at<float>(0, 1) = 1.0f;
    e.at<float>(0, 2) = 0.5f;        // 128.0 -> entry 128
    e.at<float>(0, 3) = 10.0f / 255; // entry 10
    const cv::Mat h = magma_heatmap(e);
    ASSERT_EQ(h.type(), CV_32FC3);
    const float* p = h.ptr<float>(0);
    EXPECT_FLOAT_EQ(p[0], 0.001462f);
    EXPECT_FLOAT_EQ(p[2], 0.013866f);
    EXPECT_FLOAT_EQ(p[3], 0.987053f);
    EXPECT_FLOAT_EQ(p[5], 0.749504f);
    EXPECT_FLOAT_EQ(p[6], flip::kMagma[128][0]);
    EXPECT_FLOAT_EQ(p[9 + 1], flip::kMagma[10][1]);
}

// Issue 30: one finite pixel at 1e20 overflowed the tone mapper's c * c (inf/inf = NaN); FLIP's
// running max over exposures lost the NaN, so the pixel and its neighbourhood scored 0 (or not,
// depending on how each kernel clamped the NaN). It is scored now, the same by every kernel.
TEST(Flip, AHugeFinitePixelIsScoredByEveryKernel) {
    const cv::Mat a = synthetic(64, 48, 9, 0.05f) * 2.0;
    cv::Mat hot = a.clone();
    hot.at<cv::Vec3f>(20, 30) = cv::Vec3f(1e20f, 1e20f, 1e20f);
    for (const flip::Kernels* k : flip::available_kernels()) {
        FlipOptions o;
        o.kernels = k;
        for (const bool hot_is_test : {true, false}) {
            const FlipResult r = hot_is_test ? compute_flip_hdr(a, hot, o) : compute_flip_hdr(hot, a, o);
            EXPECT_TRUE(cv::checkRange(r.errmap)) << k->name;
            // (The old code scored the pixel and its neighbours 0: the NaN lost to the running max.)
            EXPECT_GT(r.errmap.at<float>(20, 30), 0.1f) << k->name << (hot_is_test ? " hot test" : " hot reference");
            EXPECT_GT(r.errmap.at<float>(20, 31), 0.05f) << k->name << ": the neighbours see it through the filters";
            EXPECT_GT(r.mean, 0.0) << k->name;
        }
        const FlipResult same = compute_flip_hdr(hot, hot, o);
        EXPECT_EQ(same.max, 0.0) << k->name;
    }
}

// Issue 30's siblings: --ppd 1e39 (inf as a float) and 1e-39 scored any pair 0.0; given exposures
// of -1e30..1e30 overflowed the exposure count, -1e5..1e5 ran for ever.
TEST(Flip, PpdAndGivenExposuresOutsideTheirRangeAreUsageErrors) {
    const cv::Mat a = synthetic(48, 32, 10, 0.05f), b = synthetic(48, 32, 11, 0.05f);
    FlipOptions o;
    for (double ppd : {1e39, 1e-39, 0.5, 1001.0}) {
        o.ppd = ppd;
        EXPECT_THROW(compute_flip_ldr(a, b, o), UsageError) << ppd;
        EXPECT_THROW(compute_flip_hdr(a, b, o), UsageError) << ppd;
    }
    for (double ppd : {1.0, 1000.0}) {
        o.ppd = ppd;
        EXPECT_GT(compute_flip_ldr(a, b, o).mean, 0.01) << ppd;
    }
    o.ppd = flip::kDefaultPpd;
    o.start_exposure = -1e30f;
    o.stop_exposure = 1e30f;
    EXPECT_THROW(compute_flip_hdr(a, b, o), UsageError);
    o.start_exposure = std::nanf("");
    o.stop_exposure = 1.0f;
    EXPECT_THROW(compute_flip_hdr(a, b, o), UsageError);
    o.start_exposure = -126.0f;
    o.stop_exposure = 126.0f;
    EXPECT_EQ(compute_flip_hdr(a, b, o).num_exposures, 252);
}

TEST(DisplayTransform, HugeFiniteValuesSaturateToWhite) {
    // Each used to be NaN (c * c overflows float from 1.8e19).
    const float white = display_transform_channel(1e6f); // ACES clamped to 1, then sRGB
    EXPECT_NEAR(white, 1.0f, 1e-6);
    for (float v : {1e18f, 1e19f, 1e20f, 3.4e38f}) EXPECT_EQ(display_transform_channel(v), white) << v;
    EXPECT_TRUE(std::isnan(display_transform_channel(std::nanf("")))); // a NaN is not hidden
    for (flip::ToneMapper tm : {flip::ToneMapper::aces, flip::ToneMapper::hable, flip::ToneMapper::reinhard}) {
        float r = std::numeric_limits<float>::infinity(), g = 1e20f, b = 0.0f;
        flip::tone_map(tm, r, g, b);
        EXPECT_TRUE(std::isfinite(r) && std::isfinite(g) && std::isfinite(b)) << flip::tone_mapper_name(tm);
        EXPECT_GE(std::min(r, 1.0f), 1.0f) << flip::tone_mapper_name(tm); // clamped by every caller
    }
}

TEST(DisplayTransform, AcesThenSrgb) {
    EXPECT_FLOAT_EQ(display_transform_channel(0.0f), 0.0f);
    // ACES fitted at x = 0.6 * 1: (0.36*2.51 + 0.018) / (0.36*2.43 + 0.354 + 0.14) = 0.68685...
    const float aces1 = (0.36f * 2.51f + 0.018f) / (0.36f * 2.43f + 0.354f + 0.14f);
    EXPECT_NEAR(display_transform_channel(1.0f), 1.055f * std::pow(aces1, 1.0f / 2.4f) - 0.055f, 1e-6);
    EXPECT_NEAR(display_transform_channel(1e6f), 1.0f, 1e-6); // saturates (2.51/2.43 clamped)
}

} // namespace

} // namespace test_metrics_flip
