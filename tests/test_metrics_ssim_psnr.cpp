// SSIM / PSNR agreement with scikit-image on the shared test vectors, hand-computable cases for
// PSNR, relative MSE and the temporal metrics, and the image I/O edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/display_transform.h"
#include "metrics/psnr.h"
#include "metrics/ssim.h"
#include "metrics/temporal.h"
#include "tests/synthetic_image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as one unity unit (tests/CMakeLists.txt).
namespace test_metrics_ssim_psnr {

namespace {

const fs::path kVectors = fs::path(IBLCHECK_SHARED_DIR) / "flip-vectors";

nlohmann::json gen512_ldr_expected() {
    std::ifstream f(kVectors / "expected.json");
    const auto j = nlohmann::json::parse(f);
    for (const auto& p : j["pairs"])
        if (p["name"] == "gen512_ldr") return p;
    throw std::runtime_error("gen512_ldr missing from expected.json");
}

cv::Mat noise_image(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w * 3; ++x) m.ptr<float>(y)[x] = u(rng);
    return m;
}

TEST(Ssim, MatchesScikitImageOnGen512) {
    if (!fs::exists(kVectors / "expected.json"))
        GTEST_SKIP() << kVectors.string() << " not found: the shared FLIP/SSIM test vectors are absent";
    const auto p = gen512_ldr_expected();
    const auto ref = read_image((kVectors / p["reference"].get<std::string>()).string());
    const auto test = read_image((kVectors / p["test"].get<std::string>()).string());
    ASSERT_FALSE(ref.hdr);
    const SsimResult s = compute_ssim(ref.pixels, test.pixels);
    const double expected = p["ssim_skimage"].get<double>();
    std::cout << "[ gen512_ldr ] SSIM " << s.mean << " vs scikit-image " << expected << " (delta " << s.mean - expected << ")\n";
    EXPECT_NEAR(s.mean, expected, 1e-4);
    EXPECT_NEAR(s.mean, (s.per_channel[0] + s.per_channel[1] + s.per_channel[2]) / 3.0, 1e-15);
}

TEST(Psnr, MatchesScikitImageOnGen512) {
    if (!fs::exists(kVectors / "expected.json"))
        GTEST_SKIP() << kVectors.string() << " not found: the shared FLIP/SSIM test vectors are absent";
    const auto p = gen512_ldr_expected();
    const auto ref = read_image((kVectors / p["reference"].get<std::string>()).string());
    const auto test = read_image((kVectors / p["test"].get<std::string>()).string());
    const PsnrResult r = compute_psnr(ref.pixels, test.pixels);
    const double expected = p["psnr_skimage"].get<double>();
    std::cout << "[ gen512_ldr ] PSNR " << r.db << " dB vs scikit-image " << expected << " (delta " << r.db - expected << ")\n";
    EXPECT_NEAR(r.db, expected, 1e-4);
    EXPECT_NEAR(r.rmse, std::pow(10.0, -expected / 20.0), 1e-6);
}

TEST(Ssim, IdenticalIsOneAndNoiseIsLow) {
    const cv::Mat a = noise_image(64, 48, 1), b = noise_image(64, 48, 2);
    EXPECT_DOUBLE_EQ(compute_ssim(a, a).mean, 1.0);
    const double s = compute_ssim(a, b).mean;
    EXPECT_LT(s, 0.1);                              // independent noise: no structure in common
    EXPECT_NEAR(compute_ssim(b, a).mean, s, 1e-12); // symmetric
}

TEST(Ssim, ConstantImagesLuminanceTerm) {
    // Flat images: variances are 0, so SSIM = (2 mx my + C1) / (mx^2 + my^2 + C1) exactly.
    const cv::Mat a(20, 20, CV_32FC3, cv::Scalar(0.25, 0.25, 0.25));
    const cv::Mat b(20, 20, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
    const double c1 = 0.01 * 0.01;
    const double expected = (2 * 0.25 * 0.5 + c1) / (0.25 * 0.25 + 0.5 * 0.5 + c1);
    EXPECT_NEAR(compute_ssim(a, b).mean, expected, 1e-12);
}

TEST(Ssim, ValidRegionNeedsAnElevenPixelWindow) {
    // 11x11 is the smallest image with a valid region (one pixel); smaller is an input error.
    const cv::Mat f1(11, 11, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
    cv::Mat f2 = f1.clone();
    f2.at<cv::Vec3f>(5, 5) = cv::Vec3f(0.6f, 0.6f, 0.6f);
    EXPECT_DOUBLE_EQ(compute_ssim(f1, f1).mean, 1.0);
    EXPECT_LT(compute_ssim(f1, f2).mean, 1.0);
    const cv::Mat small(10, 10, CV_32FC3, cv::Scalar(0, 0, 0));
    EXPECT_THROW(compute_ssim(small, small), InputError);
}

TEST(Ssim, HdrUsesTheDisplayTransform) {
    const cv::Mat a = noise_image(40, 30, 4) * 8.0, b = noise_image(40, 30, 5) * 8.0;
    EXPECT_DOUBLE_EQ(compute_ssim_hdr(a, b).mean, compute_ssim(display_transform(a), display_transform(b)).mean);
}

TEST(Ssim, HdrWithAHugeFinitePixelIsANumber) {
    // Issue 30: a pixel at 1e20 made the display transform NaN, so SSIM was NaN (null in the JSON)
    // and a bit-identical render failed its golden forever.
    const cv::Mat a = noise_image(40, 30, 6) * 4.0;
    cv::Mat hot = a.clone();
    hot.at<cv::Vec3f>(12, 17) = cv::Vec3f(1e20f, 1e20f, 1e20f);
    EXPECT_EQ(compute_ssim_hdr(hot, hot).mean, 1.0);
    const double s = compute_ssim_hdr(a, hot).mean;
    EXPECT_TRUE(std::isfinite(s));
    EXPECT_LT(s, 1.0);
    EXPECT_GT(s, 0.9); // one pixel of 1200
}

TEST(Psnr, HandComputed) {
    const cv::Mat a(10, 10, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
    cv::Mat b = a + cv::Scalar(0.1, 0.1, 0.1);
    b.at<cv::Vec3f>(2, 3)[1] = 0.9f; // one value off by 0.4
    // MSE = (299 * 0.1^2 + 0.4^2) / 300, in float32-rounded inputs.
    const double d = double(0.5f + 0.1f) - 0.5, big = double(0.9f) - 0.5;
    const double mse = (299 * d * d + big * big) / 300.0;
    const PsnrResult r = compute_psnr(a, b);
    EXPECT_NEAR(r.mse, mse, 1e-12);
    EXPECT_NEAR(r.db, 10 * std::log10(1.0 / mse), 1e-9);
    EXPECT_NEAR(r.rmse, std::sqrt(mse), 1e-12);
    EXPECT_NEAR(r.max_abs, big, 1e-12);
    EXPECT_TRUE(std::isinf(compute_psnr(a, a).db));
}

TEST(Psnr, RelativeMseHandComputed) {
    cv::Mat r(1, 2, CV_32FC3), t(1, 2, CV_32FC3);
    r.at<cv::Vec3f>(0, 0) = {0.0f, 1.0f, 10.0f};
    t.at<cv::Vec3f>(0, 0) = {0.1f, 1.0f, 11.0f};
    r.at<cv::Vec3f>(0, 1) = {2.0f, 2.0f, 2.0f};
    t.at<cv::Vec3f>(0, 1) = {2.0f, 2.0f, 2.0f};
    const double e0 = std::pow(double(0.1f), 2) / (0.0 + 0.01);
    const double e2 = 1.0 / (100.0 + 0.01);
    EXPECT_NEAR(compute_relative_mse(r, t), (e0 + e2) / 6.0, 1e-12);
}

// Temporal metrics on a 2x1, 3-frame sequence.
TEST(Temporal, HandComputed) {
    auto frame = [](float a, float b) {
        cv::Mat m(1, 2, CV_32F);
        m.at<float>(0, 0) = a, m.at<float>(0, 1) = b;
        return m;
    };
    // Reference: pixel 0 ramps 0 -> 0.5 -> 1, pixel 1 is static at 0.5.
    const std::vector<cv::Mat> ref = {frame(0.0f, 0.5f), frame(0.5f, 0.5f), frame(1.0f, 0.5f)};
    // Test: same ramp plus a constant bias (no flicker) on pixel 0, pixel 1 flickers +-0.25.
    const std::vector<cv::Mat> test = {frame(0.25f, 0.5f), frame(0.75f, 0.75f), frame(1.25f, 0.5f)};
    const TemporalResult r = compute_temporal(test, ref);
    // |dT - dR| per (t, pixel): t=1: 0, 0.25; t=2: 0, 0.25 -> mean 0.125.
    EXPECT_DOUBLE_EQ(r.flicker, 0.125);
    // sum|dT| = 0.5 + 0.25 + 0.5 + 0.25 = 1.5; sum|dR| = 0.5 + 0 + 0.5 + 0 = 1.0.
    EXPECT_DOUBLE_EQ(r.variation_ratio, 1.5);
    EXPECT_EQ(r.frames, 3);

    const TemporalResult same = compute_temporal(ref, ref);
    EXPECT_EQ(same.flicker, 0.0);
    EXPECT_EQ(same.variation_ratio, 1.0);

    const std::vector<cv::Mat> still = {frame(0.5f, 0.5f), frame(0.5f, 0.5f)};
    const std::vector<cv::Mat> moving = {frame(0.5f, 0.5f), frame(0.7f, 0.5f)};
    EXPECT_TRUE(std::isinf(compute_temporal(moving, still).variation_ratio));
    EXPECT_EQ(compute_temporal(still, still).variation_ratio, 1.0);
    EXPECT_NEAR(compute_temporal(moving, still).flicker, 0.1, 1e-7);

    EXPECT_THROW(compute_temporal({frame(0, 0)}, {frame(0, 0)}), InputError);
    EXPECT_THROW(compute_temporal(test, still), InputError);
}

// ---------------------------------------------------------------------------------------------
// Image I/O

class ImageIo : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = testutil::temp_dir(std::string("io_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& n) const { return (dir_ / n).string(); }
    fs::path dir_;
};

TEST_F(ImageIo, PngRoundTripIsSrgbCodes) {
    cv::Mat m(2, 3, CV_32FC3);
    for (int i = 0; i < 18; ++i) m.ptr<float>(0)[i] = float(i * 13) / 255.0f;
    write_png(path("a.png"), m);
    const LoadedImage li = read_image(path("a.png"));
    EXPECT_FALSE(li.hdr);
    EXPECT_EQ(li.file_channels, 3);
    ASSERT_EQ(li.pixels.type(), CV_32FC3);
    for (int i = 0; i < 18; ++i) EXPECT_EQ(li.pixels.ptr<float>(0)[i], float(i * 13) / 255.0f);
}

TEST_F(ImageIo, ExrRoundTripIsExactFloat) {
    cv::Mat m(3, 2, CV_32FC3);
    for (int i = 0; i < 18; ++i) m.ptr<float>(0)[i] = 0.1234567f * float(i) + 100.0f * float(i % 2);
    write_exr(path("a.exr"), m);
    const LoadedImage li = read_image(path("a.exr"));
    EXPECT_TRUE(li.hdr);
    EXPECT_EQ(cv::norm(li.pixels, m, cv::NORM_INF), 0.0);
}

TEST_F(ImageIo, GreyExpandsAndAlphaIsDropped) {
    cv::Mat grey(2, 2, CV_32F, cv::Scalar(0.5));
    write_exr(path("g.exr"), grey);
    const LoadedImage g = read_image(path("g.exr"));
    EXPECT_EQ(g.file_channels, 1);
    EXPECT_EQ(g.pixels.at<cv::Vec3f>(1, 1), cv::Vec3f(0.5f, 0.5f, 0.5f));

    // RGBA written directly with OIIO.
    const float rgba[8] = {0.1f, 0.2f, 0.3f, 0.9f, 0.4f, 0.5f, 0.6f, 0.0f};
    auto out = OIIO::ImageOutput::create(path("rgba.exr"));
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out->open(path("rgba.exr"), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgba));
    out->close();
    const LoadedImage c = read_image(path("rgba.exr"));
    EXPECT_EQ(c.file_channels, 4);
    EXPECT_EQ(c.pixels.at<cv::Vec3f>(0, 1), cv::Vec3f(0.4f, 0.5f, 0.6f));
}

TEST_F(ImageIo, BadInputThrowsWithPathAndProblem) {
    try {
        read_image(path("missing.exr"));
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), path("missing.exr") + ": file not found");
    }
    {
        std::ofstream f(path("junk.exr"), std::ios::binary);
        f << "definitely not an OpenEXR file";
    }
    try {
        read_image(path("junk.exr"));
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path("junk.exr") + ": ", 0), 0u) << e.what();
    }
    // Five channels: not an image we know how to compare.
    std::vector<float> five(2 * 2 * 5, 0.5f);
    auto out = OIIO::ImageOutput::create(path("five.exr"));
    OIIO::ImageSpec spec(2, 2, 5, OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out->open(path("five.exr"), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, five.data()));
    out->close();
    try {
        read_image(path("five.exr"));
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("unsupported channel count 5"), std::string::npos) << e.what();
    }
}

TEST(Validation, FiniteNegativeAndSize) {
    cv::Mat m(4, 5, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
    EXPECT_NO_THROW(check_finite(m, "a.exr"));
    m.at<cv::Vec3f>(2, 4)[2] = std::numeric_limits<float>::infinity();
    m.at<cv::Vec3f>(3, 0)[0] = std::nanf("");
    try {
        check_finite(m, "a.exr");
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "a.exr: 2 non-finite value(s) (NaN/Inf), first at x=4, y=2");
    }
    cv::Mat n(2, 2, CV_32FC3, cv::Scalar(1, -1, 0.5));
    n.at<cv::Vec3f>(0, 0)[2] = -3.0f;
    EXPECT_EQ(count_negative(n), 5u);
    EXPECT_EQ(clamp_negative(n), 5u);
    EXPECT_EQ(count_negative(n), 0u);
    EXPECT_EQ(n.at<cv::Vec3f>(0, 0), cv::Vec3f(1, 0, 0));
    EXPECT_NO_THROW(check_same_size(n, n, "a", "b"));
    try {
        check_same_size(n, m, "a.png", "b.png");
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "b.png: size 5x4 does not match a.png (2x2)");
    }
}

} // namespace

// Issue 33: bit-identical finite inputs (a render equal to its baseline) skip SSIM's filtering and
// PSNR's loop; the skipped result is the evaluated one bit for bit (SSIM 1.0 per channel, PSNR
// +inf with MSE, RMSE and max_abs +0.0), on goldens, an HDR image with a 1e4 highlight, tiny values
// and an LDR image. An image with a NaN is not skipped (its figures stay NaN).
TEST(SsimPsnr, IdenticalInputsSkipWithTheSameResult) {
    using testing_support::synthetic;
    std::vector<cv::Mat> images;
    for (const char* g :
         {"goldens/baseline/mobile.roughness_sweep.sky_sun.default.exr", "goldens/reference/furnace__constant-1.exr"})
        images.push_back(display_transform(read_image(std::string(IBLCHECK_SOURCE_DIR) + "/" + g).pixels));
    cv::Mat hdr = synthetic(97, 61, 3, 0.1f) * 8.0;
    hdr.at<cv::Vec3f>(10, 20) = cv::Vec3f(1e4f, 9e3f, 8e3f);
    images.push_back(display_transform(hdr));
    images.push_back(synthetic(64, 48, 5, 0.0f) * 1e-30);
    images.push_back(synthetic(40, 33, 7, 0.05f));
    for (const cv::Mat& img : images) {
        ASSERT_FALSE(img.empty());
        const SsimResult s = compute_ssim(img, img.clone()), se = compute_ssim(img, img.clone(), false);
        EXPECT_EQ(std::memcmp(&s, &se, sizeof s), 0) << se.mean;
        EXPECT_EQ(se.mean, 1.0); // what the skip assumes
        const PsnrResult p = compute_psnr(img, img.clone()), pe = compute_psnr(img, img.clone(), 1.0, false);
        EXPECT_EQ(std::memcmp(&p, &pe, sizeof p), 0) << pe.db << " " << pe.rmse;
        EXPECT_TRUE(std::isinf(pe.db));
    }
    cv::Mat nan = synthetic(32, 32, 9, 0.0f);
    nan.at<cv::Vec3f>(16, 16)[1] = std::nanf("");
    EXPECT_TRUE(std::isnan(compute_ssim(nan, nan.clone()).mean));
    EXPECT_TRUE(std::isnan(compute_psnr(nan, nan.clone()).rmse));
}

} // namespace test_metrics_ssim_psnr
