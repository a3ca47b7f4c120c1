// `iblcheck compare` in-process (run_compare, run_compare_pairs): JSON and human output, every kind
// of bad input (missing, corrupt, size or channel mismatch, NaN/Inf, negative HDR), batch pairs,
// PNG alpha, black HDR references and images under SSIM's window.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <CLI/CLI.hpp>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "cli/compare_command.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/catalog.h"
#include "metrics/image_compare.h"
#include "metrics/psnr.h"
#include "tests/synthetic_image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using iblcheck::testing_support::synthetic;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_compare_command {

namespace {

class CompareCommand : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = testutil::temp_dir(std::string("compare_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    int run(CompareArgs a) {
        out_.str(""), err_.str("");
        return run_compare(a, out_, err_);
    }
    CompareArgs args(const std::string& r, const std::string& t) {
        CompareArgs a;
        a.reference = r, a.test = t;
        return a;
    }
    fs::path dir_;
    std::ostringstream out_, err_;
};

TEST_F(CompareCommand, LdrPairJson) {
    const cv::Mat a = synthetic(64, 48, 7, 0.02f), b = synthetic(64, 48, 8, 0.05f);
    write_png(path("a.png"), a);
    write_png(path("b.png"), b);
    CompareArgs c = args(path("a.png"), path("b.png"));
    c.json = true;
    c.heatmap = path("heat.png");
    c.errmap = path("err.exr");
    ASSERT_EQ(run(c), 0) << err_.str();
    const auto j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["flip"]["mode"], "ldr");
    EXPECT_GT(j["flip"]["mean"].get<double>(), 0.0);
    EXPECT_LT(j["ssim"]["mean"].get<double>(), 1.0);
    EXPECT_GT(j["psnr"]["db"].get<double>(), 10.0);
    EXPECT_FALSE(j["flip"].contains("start_exposure"));
    EXPECT_TRUE(fs::exists(path("heat.png")));
    const auto err = read_image(path("err.exr"));
    EXPECT_EQ(err.file_channels, 1);
    EXPECT_EQ(err.pixels.cols, 64);
}

TEST_F(CompareCommand, HdrPairOnlyFlipAndHumanTable) {
    cv::Mat a = synthetic(40, 40, 9, 0.0f) * 5.0, b = synthetic(40, 40, 10, 0.1f) * 5.0;
    write_exr(path("a.exr"), a);
    write_exr(path("b.exr"), b);
    CompareArgs c = args(path("a.exr"), path("b.exr"));
    c.metric = "flip";
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    const auto j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["flip"]["mode"], "hdr");
    EXPECT_TRUE(j["flip"].contains("num_exposures"));
    EXPECT_FALSE(j.contains("ssim"));
    EXPECT_FALSE(j.contains("psnr"));
    c.json = false;
    c.metric = "all";
    ASSERT_EQ(run(c), 0) << err_.str();
    EXPECT_NE(out_.str().find("HDR-FLIP exposures"), std::string::npos) << out_.str();
    EXPECT_NE(out_.str().find("SSIM"), std::string::npos);
}

// Issue 31: `compare` gave psnr.db on the linear radiance (a ci render against its truth: 9.41 dB),
// `run` after the display transform (20.94 dB): one key, two quantities. Now `compare` makes the
// runner's comparison (compare_images with the runner's arguments) and gives the same value for
// every key the runner records; the radiance's PSNR has its own key, linear_psnr.db.
TEST_F(CompareCommand, GivesTheRunnersValueForEveryKey) {
    // Radiance above 1, as a render has (the linear and the display PSNR then differ most).
    cv::Mat a = synthetic(48, 40, 11, 0.02f) * 4.0, b = synthetic(48, 40, 12, 0.1f) * 4.0;
    write_exr(path("golden.exr"), a);
    write_exr(path("render.exr"), b);
    CompareArgs c = args(path("golden.exr"), path("render.exr"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    const auto cmd = nlohmann::json::parse(out_.str());
    // The runner's comparison of the same files (golden_comparisons.cpp's measure of a test without
    // a display space).
    const cv::Mat golden = read_image(path("golden.exr")).pixels, render = read_image(path("render.exr")).pixels;
    const auto runner = compare_images(golden, render, 0);
    int keys = 0;
    for (const MetricInfo* k : judged_metrics(false)) {
        ASSERT_TRUE(runner[k->group][k->field].is_number()) << k->key;
        EXPECT_EQ(cmd[k->group][k->field], runner[k->group][k->field]) << k->key;
        ++keys;
    }
    EXPECT_EQ(keys, 5); // flip.mean, flip.p99, flip.block_max, ssim.mean, psnr.db
    // The radiance's PSNR under its own key, and another quantity than psnr.db.
    const PsnrResult linear = compute_psnr(golden, render);
    EXPECT_EQ(cmd["linear_psnr"]["db"].get<double>(), linear.db);
    EXPECT_EQ(cmd["linear_psnr"]["relative_mse"].get<double>(), compute_relative_mse(golden, render));
    EXPECT_GT(std::fabs(cmd["psnr"]["db"].get<double>() - linear.db), 1.0);
}

TEST_F(CompareCommand, MissingFile) {
    write_png(path("a.png"), synthetic(16, 16, 1, 0));
    EXPECT_EQ(run(args(path("a.png"), path("nope.png"))), kExitError);
    EXPECT_NE(err_.str().find("error: " + path("nope.png") + ": file not found"), std::string::npos) << err_.str();
}

TEST_F(CompareCommand, CorruptFile) {
    write_png(path("a.png"), synthetic(16, 16, 1, 0));
    {
        std::ofstream f(path("bad.png"), std::ios::binary);
        f << "\x89PNG\r\n\x1a\n this is not really a png";
    }
    EXPECT_EQ(run(args(path("a.png"), path("bad.png"))), kExitError);
    EXPECT_NE(err_.str().find("error: " + path("bad.png") + ":"), std::string::npos) << err_.str();
}

TEST_F(CompareCommand, SizeMismatch) {
    write_png(path("a.png"), synthetic(16, 16, 1, 0));
    write_png(path("b.png"), synthetic(17, 16, 1, 0));
    EXPECT_EQ(run(args(path("a.png"), path("b.png"))), kExitError);
    EXPECT_NE(err_.str().find(path("b.png") + ": size 17x16 does not match"), std::string::npos) << err_.str();
}

TEST_F(CompareCommand, ChannelMismatch) {
    write_png(path("rgb.png"), synthetic(16, 16, 1, 0));
    cv::Mat grey(16, 16, CV_32F, cv::Scalar(0.5));
    write_png(path("grey.png"), grey);
    EXPECT_EQ(run(args(path("rgb.png"), path("grey.png"))), kExitError);
    EXPECT_NE(err_.str().find(path("grey.png") + ": has 1 channel(s) but"), std::string::npos) << err_.str();
}

TEST_F(CompareCommand, NanAndInfPixels) {
    cv::Mat a = synthetic(20, 10, 1, 0), b = a.clone();
    b.at<cv::Vec3f>(3, 7)[1] = std::numeric_limits<float>::quiet_NaN();
    b.at<cv::Vec3f>(8, 2)[0] = std::numeric_limits<float>::infinity();
    write_exr(path("a.exr"), a);
    write_exr(path("b.exr"), b);
    EXPECT_EQ(run(args(path("a.exr"), path("b.exr"))), kExitError);
    EXPECT_NE(err_.str().find(path("b.exr") + ": 2 non-finite value(s) (NaN/Inf), first at x=7, y=3"), std::string::npos)
        << err_.str();
}

TEST_F(CompareCommand, NegativeHdrValuesFailOrClamp) {
    cv::Mat a = synthetic(20, 20, 1, 0), b = a.clone();
    b.at<cv::Vec3f>(5, 5)[2] = -0.5f;
    b.at<cv::Vec3f>(6, 5)[0] = -1.0f;
    write_exr(path("a.exr"), a);
    write_exr(path("b.exr"), b);
    EXPECT_EQ(run(args(path("a.exr"), path("b.exr"))), kExitError);
    EXPECT_NE(err_.str().find(path("b.exr") + ": 2 negative value(s)"), std::string::npos) << err_.str();
    CompareArgs c = args(path("a.exr"), path("b.exr"));
    c.clamp_negative = true;
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    const auto j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["clamped_negative"]["test"].get<int>(), 2);
    EXPECT_EQ(j["clamped_negative"]["reference"].get<int>(), 0);
}

TEST_F(CompareCommand, BadMetricIsUsageError) {
    write_png(path("a.png"), synthetic(16, 16, 1, 0));
    CompareArgs c = args(path("a.png"), path("a.png"));
    c.metric = "lpips";
    EXPECT_EQ(run(c), kExitError);
    EXPECT_NE(err_.str().find("--metric"), std::string::npos);
}

TEST_F(CompareCommand, RegisteredSubcommandParsesOptions) {
    write_png(path("a.png"), synthetic(24, 24, 1, 0.1f));
    write_png(path("b.png"), synthetic(24, 24, 2, 0.1f));
    CLI::App app("iblcheck");
    int exit_code = -1;
    register_compare_command(app, exit_code);
    std::vector<std::string> argv = {"compare", path("a.png"), path("b.png"), "--metric",  "flip",
                                     "--ppd",   "40",          "--json",      "--heatmap", path("h.png")};
    std::reverse(argv.begin(), argv.end()); // CLI11 parses a reversed vector
    testing::internal::CaptureStdout();
    app.parse(argv);
    const std::string printed = testing::internal::GetCapturedStdout();
    EXPECT_EQ(exit_code, 0);
    const auto j = nlohmann::json::parse(printed);
    EXPECT_NEAR(j["flip"]["ppd"].get<double>(), 40.0, 1e-6);
    EXPECT_FALSE(j.contains("ssim"));
    EXPECT_TRUE(fs::exists(path("h.png")));

    CLI::App app2("iblcheck");
    register_compare_command(app2, exit_code);
    std::vector<std::string> bad = {"compare", path("a.png"), path("b.png"), "--mode", "xyz"};
    std::reverse(bad.begin(), bad.end());
    EXPECT_THROW(app2.parse(bad), CLI::ValidationError);
}

TEST_F(CompareCommand, IdenticalImagesPerfectScores) {
    write_png(path("a.png"), synthetic(32, 32, 1, 0.1f));
    CompareArgs c = args(path("a.png"), path("a.png"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    const auto j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["flip"]["mean"].get<double>(), 0.0);
    EXPECT_DOUBLE_EQ(j["ssim"]["mean"].get<double>(), 1.0);
    EXPECT_EQ(j["psnr"]["db"].get<double>(), kPsnrIdentical); // +inf, written as `run` writes it
}

TEST(ComparePairsList, ParsesLines) {
    EXPECT_EQ(parse_pair_line("").kind, PairLine::Kind::blank);
    EXPECT_EQ(parse_pair_line("   # ref test").kind, PairLine::Kind::blank);
    PairLine p = parse_pair_line("  a.png   b.png \r");
    ASSERT_EQ(p.kind, PairLine::Kind::pair);
    EXPECT_EQ(p.reference, "a.png");
    EXPECT_EQ(p.test, "b.png");
    p = parse_pair_line("my renders/a.png\tmy renders/b.png");
    ASSERT_EQ(p.kind, PairLine::Kind::pair);
    EXPECT_EQ(p.reference, "my renders/a.png");
    EXPECT_EQ(p.test, "my renders/b.png");
    p = parse_pair_line("a.png b.png c.png");
    EXPECT_EQ(p.kind, PairLine::Kind::bad);
    EXPECT_EQ(p.problem, "expected 2 paths (REF TEST), found 3");
    EXPECT_EQ(parse_pair_line("only.png").kind, PairLine::Kind::bad);
}

TEST_F(CompareCommand, PairsGiveOneJsonLinePerPairWithTheSingleCompareValues) {
    write_png(path("a.png"), synthetic(40, 32, 1, 0.02f));
    write_png(path("b.png"), synthetic(40, 32, 2, 0.05f));
    write_exr(path("a.exr"), synthetic(40, 32, 3, 0.0f) * 3.0);
    write_exr(path("b.exr"), synthetic(40, 32, 4, 0.1f) * 3.0);
    std::istringstream list(path("a.png") + " " + path("b.png") + "\n" + path("a.exr") + " " + path("b.exr") + "\n");
    CompareArgs all;
    ASSERT_EQ(run_compare_pairs(all, list, "list.txt", out_, err_), 0) << err_.str();
    std::vector<nlohmann::json> lines;
    std::istringstream ss(out_.str());
    for (std::string l; std::getline(ss, l);) lines.push_back(nlohmann::json::parse(l));
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_NE(err_.str().find("compared 2 pair(s)"), std::string::npos) << err_.str();
    // Each line holds what `compare --json` prints for that pair alone, plus where it came from.
    for (size_t i = 0; i < 2; ++i) {
        const std::string ref = lines[i]["reference"], test = lines[i]["test"];
        CompareArgs one = args(ref, test);
        one.json = true;
        std::ostringstream o, e;
        ASSERT_EQ(run_compare(one, o, e), 0) << e.str();
        nlohmann::json single = nlohmann::json::parse(o.str());
        nlohmann::json batched = lines[i];
        EXPECT_EQ(batched["line"], int(i) + 1);
        batched.erase("reference"), batched.erase("test"), batched.erase("line");
        EXPECT_EQ(batched, single) << ref;
    }
    EXPECT_EQ(lines[1]["flip"]["mode"], "hdr");
}

TEST_F(CompareCommand, PairsReportEveryFailureAndExit2) {
    write_png(path("a.png"), synthetic(16, 16, 1, 0));
    write_png(path("small.png"), synthetic(8, 8, 1, 0));
    std::istringstream list(path("a.png") + " " + path("nope.png") + "\n" + "one-path-only\n" + path("a.png") + " " +
                            path("small.png") + "\n" + path("a.png") + " " + path("a.png") + "\n");
    CompareArgs c;
    c.metric = "psnr";
    EXPECT_EQ(run_compare_pairs(c, list, "pairs.txt", out_, err_), kExitError);
    std::vector<nlohmann::json> lines;
    std::istringstream ss(out_.str());
    for (std::string l; std::getline(ss, l);) lines.push_back(nlohmann::json::parse(l));
    ASSERT_EQ(lines.size(), 4u) << out_.str();
    EXPECT_EQ(lines[0]["error"], path("nope.png") + ": file not found");
    EXPECT_EQ(lines[1]["error"], "pairs.txt: line 2: expected 2 paths (REF TEST), found 1");
    EXPECT_NE(lines[2]["error"].get<std::string>().find(path("small.png") + ": size 8x8 does not match"), std::string::npos)
        << lines[2];
    EXPECT_EQ(lines[3]["psnr"]["db"].get<double>(), kPsnrIdentical); // identical: the good pair is still compared
    EXPECT_NE(err_.str().find("compared 1 pair(s), 3 could not be compared"), std::string::npos) << err_.str();
}

TEST_F(CompareCommand, PairsRefusePerPairOutputsAndBadOptionsBeforeReading) {
    std::istringstream list("a.png b.png\n");
    CompareArgs c;
    c.heatmap = path("h.png");
    EXPECT_EQ(run_compare_pairs(c, list, "l", out_, err_), kExitError);
    EXPECT_NE(err_.str().find("not with --pairs"), std::string::npos) << err_.str();
    EXPECT_EQ(out_.str(), "");
    CompareArgs bad;
    bad.metric = "lpips";
    EXPECT_EQ(run_compare_pairs(bad, list, "l", out_, err_), kExitError);
    EXPECT_NE(err_.str().find("--metric"), std::string::npos);
}

} // namespace

// Writes an 8-bit RGBA PNG (OpenImageIO, unassociated alpha as PNG stores it).
static void write_rgba_png(const std::string& file, const cv::Mat& rgb, float alpha) {
    std::vector<unsigned char> px(size_t(rgb.total()) * 4);
    for (int y = 0, i = 0; y < rgb.rows; ++y)
        for (int x = 0; x < rgb.cols; ++x, i += 4) {
            const cv::Vec3f c = rgb.at<cv::Vec3f>(y, x);
            for (int k = 0; k < 3; ++k) px[size_t(i + k)] = (unsigned char)(std::clamp(c[k], 0.0f, 1.0f) * 255.0f + 0.5f);
            px[size_t(i + 3)] = (unsigned char)(alpha * 255.0f + 0.5f);
        }
    auto out = OIIO::ImageOutput::create(file);
    OIIO::ImageSpec spec(rgb.cols, rgb.rows, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);
    ASSERT_TRUE(out && out->open(file, spec) && out->write_image(OIIO::TypeDesc::UINT8, px.data()));
    out->close();
}

TEST_F(CompareCommand, RgbaPngColourIsReadAsStoredNotPremultiplied) {
    // Issue 14: OpenImageIO premultiplied colour by alpha, so an RGBA pair scored FLIP 0.188 where
    // NVIDIA's tool (which scores the stored colour) gives 0.0155. The colour of an RGBA PNG now
    // reads exactly as stored, so an RGBA pair scores what the same colours score as RGB.
    const cv::Mat a = synthetic(64, 48, 7, 0.02f), b = synthetic(64, 48, 8, 0.05f);
    write_rgba_png(path("a.png"), a, 0.25f);
    write_rgba_png(path("b.png"), b, 0.25f);
    write_png(path("a_rgb.png"), a);
    write_png(path("b_rgb.png"), b);
    const LoadedImage la = read_image(path("a.png")), la_rgb = read_image(path("a_rgb.png"));
    EXPECT_EQ(la.file_channels, 4);
    EXPECT_TRUE(la.has_alpha());
    EXPECT_EQ(cv::norm(la.pixels, la_rgb.pixels, cv::NORM_INF), 0.0); // not scaled by 0.25
    CompareArgs c = args(path("a.png"), path("b.png"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    const double rgba = nlohmann::json::parse(out_.str())["flip"]["mean"];
    c = args(path("a_rgb.png"), path("b_rgb.png"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    EXPECT_EQ(rgba, nlohmann::json::parse(out_.str())["flip"]["mean"].get<double>());
    // RGB against RGBA is refused, naming both files (alpha would be silently ignored on one side).
    EXPECT_EQ(run(args(path("a_rgb.png"), path("b.png"))), kExitError);
    EXPECT_NE(err_.str().find(path("b.png") + ": has 4 channel(s) but " + path("a_rgb.png") + " has 3"), std::string::npos)
        << err_.str();
}

TEST_F(CompareCommand, BlackHdrReferenceTakesExposuresFromTheTestAndSaysSo) {
    // Issue 14: with an all-black reference the tool's exposure range is infinite and every test
    // scored 0 (a white test passed). The range now comes from the test image, and the output says so.
    cv::Mat black(32, 32, CV_32FC3, cv::Scalar(0, 0, 0)), white(32, 32, CV_32FC3, cv::Scalar(1, 1, 1));
    write_exr(path("black.exr"), black);
    write_exr(path("white.exr"), white);
    CompareArgs c = args(path("black.exr"), path("white.exr"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    auto j = nlohmann::json::parse(out_.str());
    EXPECT_GT(j["flip"]["mean"].get<double>(), 0.5);
    EXPECT_EQ(j["flip"]["exposure_source"], "test (the reference is black)");
    EXPECT_TRUE(std::isfinite(j["flip"]["start_exposure"].get<double>()));
    // Both black: identical images, FLIP 0 with a finite range.
    c = args(path("black.exr"), path("black.exr"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["flip"]["mean"].get<double>(), 0.0);
    EXPECT_EQ(j["flip"]["exposure_source"], "none (both images are black)");
    // A reference lit in under half its pixels (black median): the median of the lit pixels.
    cv::Mat spot = black.clone();
    spot(cv::Rect(0, 0, 8, 8)).setTo(cv::Scalar(2, 2, 2));
    write_exr(path("spot.exr"), spot);
    c = args(path("spot.exr"), path("white.exr"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    j = nlohmann::json::parse(out_.str());
    EXPECT_EQ(j["flip"]["exposure_source"], "reference (median of its lit pixels)");
    EXPECT_TRUE(std::isfinite(j["flip"]["stop_exposure"].get<double>()));
    EXPECT_GT(j["flip"]["mean"].get<double>(), 0.3);
}

TEST_F(CompareCommand, ImagesUnderSsimsWindowGetFlipAndPsnrAndSsimNotApplicable) {
    // Issue 14: an 8x8 pair exited 2 ("SSIM: images must be at least 11x11", no file named) and
    // withheld FLIP. Now FLIP and PSNR are reported and SSIM is marked not applicable.
    write_png(path("a.png"), synthetic(8, 8, 1, 0.0f));
    write_png(path("b.png"), synthetic(8, 8, 2, 0.1f));
    CompareArgs c = args(path("a.png"), path("b.png"));
    c.json = true;
    ASSERT_EQ(run(c), 0) << err_.str();
    auto j = nlohmann::json::parse(out_.str());
    EXPECT_GT(j["flip"]["mean"].get<double>(), 0.0);
    EXPECT_GT(j["psnr"]["db"].get<double>(), 0.0);
    EXPECT_TRUE(j["ssim"]["mean"].is_null());
    EXPECT_NE(j["ssim"]["not_applicable"].get<std::string>().find("11x11"), std::string::npos);
    c.json = false;
    ASSERT_EQ(run(c), 0) << err_.str();
    EXPECT_NE(out_.str().find("SSIM not applicable"), std::string::npos) << out_.str();
}
} // namespace test_compare_command
