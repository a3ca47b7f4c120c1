// What the HTML report is built from (issues 8, 17), on the synthetic run of
// tests/report_fixture.h: the results schema's errors, the history file and what it flags
// (drift.h), the float data scripts the viewer decodes, the words a failure prints (the terminal
// and the card), and the `iblcheck report` command. The page itself: test_report.cpp.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <fstream>

#include <zlib.h>

#include "cli/report_command.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "reports/drift.h"
#include "reports/float_data.h"
#include "reports/report_writer.h"
#include "reports/verdict_text.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report_data {

TEST(Report, MalformedResultsNameFileAndProblem) {
    auto& f = testutil::small_run();
    auto expect_error = [&](json r, const std::string& what) {
        try {
            report::write_report(r, f.root / "bad", f.root / "bad_out");
            ADD_FAILURE() << "no error for " << what;
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find((f.root / "bad" / "results.json").string()), std::string::npos) << msg;
            EXPECT_NE(msg.find(what), std::string::npos) << msg;
        }
    };
    json r = f.results;
    r.erase("schema");
    expect_error(r, "missing key 'schema'");
    r = f.results;
    r["schema"] = "iblcheck-results/2";
    expect_error(r, "iblcheck-results/1");
    r = f.results;
    r.erase("tests");
    expect_error(r, "'tests'");
    r = f.results;
    r["tests"][1].erase("verdict");
    expect_error(r, "tests[1] (mobile.roughness_sweep.studio.dominant_dir=lagarde): missing key 'verdict'");
    r = f.results;
    r["tests"][0]["verdict"] = "meh";
    expect_error(r, "verdict 'meh' is not one of");
    r = f.results;
    r["tests"][0]["frame_ms"] = "fast";
    expect_error(r, "'frame_ms' must be a number");
    r = f.results;
    r["tests"][5]["temporal"]["frames"][3] = 7;
    expect_error(r, "temporal: 'frames[3]' must be a string");

    // read_results: not JSON / missing file.
    fs::create_directories(f.root / "bad");
    std::ofstream(f.root / "bad" / "broken.json") << "{\"schema\": ";
    EXPECT_THROW(report::read_results(f.root / "bad" / "broken.json"), InputError);
    EXPECT_THROW(report::read_results(f.root / "bad" / "nope.json"), InputError);
    EXPECT_NO_THROW(report::read_results(f.results_dir / "results.json"));
}

TEST(Report, HistoryFile) {
    auto& f = testutil::small_run();
    EXPECT_TRUE(report::read_history(f.root / "no_such_history.jsonl").empty());
    ASSERT_EQ(f.history.size(), 6u);
    const json e = report::history_entry(f.results);
    EXPECT_EQ(e["commit"], "f554dd9");
    EXPECT_EQ(e["date"], "2026-11-22T15:40:00Z");
    EXPECT_EQ(e["suite"], "ci");
    const json& t2 = e["tests"]["mobile.roughness_sweep.studio.dominant_dir=lagarde"];
    EXPECT_EQ(t2["verdict"], "fail");
    EXPECT_DOUBLE_EQ(t2["flip_mean"].get<double>(), 0.052);
    EXPECT_DOUBLE_EQ(t2["frame_ms"].get<double>(), 3.2);
    EXPECT_DOUBLE_EQ(t2["precompute_ms"].get<double>(), 40.1);
    EXPECT_FALSE(t2.contains("flicker"));
    EXPECT_DOUBLE_EQ(e["tests"]["mobile.rotation.sky_sun.temporal"]["flicker"].get<double>(), 0.01);
    // The repeated timings' range and the deterministic cost go into the history too.
    const json& t1 = e["tests"]["sampled.roughness_sweep.studio.samples=64"];
    EXPECT_DOUBLE_EQ(t1["frame_ms"].get<double>(), 31.0);
    EXPECT_DOUBLE_EQ(t1["frame_ms_lo"].get<double>(), 24.0);
    EXPECT_DOUBLE_EQ(t1["frame_ms_hi"].get<double>(), 70.0);
    EXPECT_EQ(t1["frame_n"], 3);
    EXPECT_DOUBLE_EQ(t1["spirv_ipp"].get<double>(), 54000.0);
    // The accuracy's noise floor: --stability's measured floor first, else the truth's seed noise.
    json r = f.results;
    r["tests"][0]["accuracy"]["noise_floor"] = {{"mean_flip", 0.0017}};
    EXPECT_DOUBLE_EQ(report::history_entry(r)["tests"]["sampled.roughness_sweep.studio.samples=64"]["flip_noise"].get<double>(),
                     0.0017);
    r["tests"][0]["stability"] = {{"noise_floor", {{"accuracy.flip.mean", 0.004}}}};
    EXPECT_DOUBLE_EQ(report::history_entry(r)["tests"]["sampled.roughness_sweep.studio.samples=64"]["flip_noise"].get<double>(),
                     0.004);
    EXPECT_EQ(e.dump().find('\n'), std::string::npos);

    const fs::path bad = f.root / "bad_history.jsonl";
    std::ofstream(bad) << e.dump() << "\n{not json\n";
    try {
        report::read_history(bad);
        ADD_FAILURE() << "no error";
    } catch (const InputError& err) {
        EXPECT_NE(std::string(err.what()).find(bad.string() + ":2:"), std::string::npos) << err.what();
    }
}

TEST(Report, ReportCommandRebuildsFromStoredResults) {
    auto& f = testutil::small_run();
    const fs::path out = f.root / "cli_out";
    CLI::App app;
    int exit_code = -1;
    cli::register_report_command(app, exit_code);
    const std::string res = (f.results_dir / "results.json").string(), o = out.string(), h = (f.root / "history.jsonl").string();
    std::vector<std::string> args{h, "--history", o, "--out", res, "report"}; // CLI11 wants them reversed
    app.parse(args);
    EXPECT_EQ(exit_code, 0);
    const std::string html = testutil::read_text(out / "index.html");
    EXPECT_NE(html.find("data-chart=\"history-flip_mean\""), std::string::npos);
    EXPECT_TRUE(fs::exists(out / "images/t2/test.png"));
}

// ---- what the history flags (drift.h) ----

TEST(Drift, AccuracyMovesAreFlaggedBeyondTheNoiseFloorOnly) {
    using report::accuracy_flag;
    const std::vector<std::string> c{"a", "b", "c", "d", "e"};
    // +3 % (0.2300 -> 0.2369) is beyond a floor of 0.0017: flagged at the commit that made it.
    auto f = accuracy_flag({0.2300, 0.2301, 0.2299, 0.2369, 0.2370}, c, 0.0017);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, 3u);
    EXPECT_EQ(f->text, "+3.0 % at d (noise floor 0.0017)");
    // Steps within the floor are noise...
    EXPECT_FALSE(accuracy_flag({0.2300, 0.2310, 0.2300, 0.2312, 0.2305}, c, 0.0017));
    // ...unless they add up to more than it: a slow drift is flagged from first to last.
    f = accuracy_flag({0.2300, 0.2312, 0.2324, 0.2336, 0.2348}, c, 0.0017);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, 4u);
    EXPECT_EQ(f->text, "+2.1 % over 5 runs since a (noise floor 0.0017)");
    // Runs without the value are skipped; one value is no trend.
    EXPECT_FALSE(accuracy_flag({std::nullopt, 0.23, std::nullopt}, {"a", "b", "c"}, 0.0));
    f = accuracy_flag({0.23, std::nullopt, 0.25}, {"a", "b", "c"}, 0.001);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, 2u);
}

TEST(Drift, TimingIsFlaggedOnlyOutsideItsMeasuredSpread) {
    using report::Spread;
    using report::timing_flag;
    const std::vector<std::string> c{"a", "b", "c", "d", "e"};
    // 2.2-5.5x noise between identical runs: a median of 12 inside [5, 14] is not a change.
    std::vector<std::optional<Spread>> s{Spread{5, 6, 11}, Spread{6, 9, 14}, Spread{5.5, 7, 12}, Spread{9, 12, 13}};
    EXPECT_FALSE(timing_flag(s, c));
    // A run whose whole range lies above everything measured before it is.
    s.push_back(Spread{30, 33, 35});
    auto f = timing_flag(s, c);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, 4u);
    EXPECT_NE(f->text.find("at e (outside the 5\u201314 measured before)"), std::string::npos) << f->text;
    // Two runs are needed before anything can be judged.
    EXPECT_FALSE(timing_flag({Spread{1, 1, 1}, Spread{9, 9, 9}}, c));
    // Just outside a narrow hull is a new extreme, not a change: 14.5 is 0.5 beyond [5, 14] (9 wide).
    EXPECT_FALSE(timing_flag({Spread{5, 6, 11}, Spread{6, 9, 14}, Spread{14.5, 15, 16}}, c));
    // Faster counts too.
    f = timing_flag({Spread{10, 11, 12}, Spread{10, 11, 13}, Spread{3, 3.5, 4}}, c);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->index, 2u);
    EXPECT_EQ(f->text.rfind("-65.0 % at c", 0), 0u) << f->text;
}

// ---- the float data the page's viewer decodes (float_data.h) ----

TEST(FloatData, HalfFloatsSurviveThePackingAndTheAutoExposureSeesTheBrightEnd) {
    cv::Mat m(4, 8, CV_32FC3);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) m.at<cv::Vec3f>(y, x) = cv::Vec3f(0.1f * float(x), 1.0f / float(1 + y), 1e5f * float(x == 7));
    const std::vector<uint16_t> h = report::to_half(m);
    ASSERT_EQ(h.size(), 96u);
    EXPECT_EQ(h[1], 0x3c00) << "1.0";
    EXPECT_EQ(h[3 * 7 + 2], 0x7bff) << "1e5 is clamped to 65504, not infinity";
    EXPECT_EQ(h[3 * 1 + 0], 0x2e66) << "0.1 rounds to nearest even";
    const std::vector<uint8_t> planes = report::unpack(report::pack_half(h));
    ASSERT_EQ(planes.size(), 192u);
    for (size_t i = 0; i < h.size(); ++i) ASSERT_EQ(uint16_t(planes[i] | planes[h.size() + i] << 8), h[i]) << i;
    EXPECT_EQ(report::base64("Man"), "TWFu");
    EXPECT_EQ(report::base64("Ma"), "TWE=");
    EXPECT_EQ(report::base64("M"), "TQ==");
    // Auto exposure: the 99th percentile of a constant image of luminance 4 reaches 0.85 after
    // the tone map: the ACES fit with the 0.6 pre-exposure gives 0.852 at x = 2.14, so log2(2.14 / 4) = -0.9.
    cv::Mat c4(8, 8, CV_32FC3, cv::Scalar(4, 4, 4));
    EXPECT_NEAR(report::auto_exposure(c4), -0.9, 0.05);
    EXPECT_DOUBLE_EQ(report::auto_exposure(cv::Mat(8, 8, CV_32FC3, cv::Scalar(0, 0, 0))), 0.0);
    // A sun in one pixel of 100 does not set the exposure.
    cv::Mat sun(10, 10, CV_32FC3, cv::Scalar(4, 4, 4));
    sun.at<cv::Vec3f>(0, 0) = cv::Vec3f(1e5f, 1e5f, 1e5f);
    EXPECT_NEAR(report::auto_exposure(sun), report::auto_exposure(c4), 0.05);
}

// The page's data at zlib's fastest level (issue 33): level 6 was most of the report's time. The
// packed bytes are level 1's and inflate to the same bytes.
TEST(FloatData, PackingIsZlibsFastestLevel) {
    std::vector<uint8_t> bytes(20000);
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t((i * i / 7 + i / 300) & 0xff);
    const std::string packed = report::pack_bytes(bytes);
    EXPECT_EQ(report::unpack(packed), bytes);
    for (int level : {1, 6}) {
        uLongf n = compressBound(uLong(bytes.size()));
        std::string z(n, '\0');
        ASSERT_EQ(compress2(reinterpret_cast<Bytef*>(z.data()), &n, bytes.data(), uLong(bytes.size()), level), Z_OK);
        z.resize(n);
        EXPECT_EQ(packed == z, level == 1) << "level " << level;
    }
}

// DataStore::prepare() reads and packs on several threads what image() then writes: the same figures
// and the same data script as image() alone, and what the page never asks for is never written.
TEST(FloatData, PreparedImagesAreWrittenAsImageWritesThemAndOnlyWhenAsked) {
    const fs::path dir = testutil::temp_dir("float_data_prepare");
    fs::create_directories(dir / "images");
    std::vector<std::string> rels;
    for (int k = 0; k < 5; ++k) {
        cv::Mat m(12, 20, CV_32FC3);
        cv::randu(m, 0.0f, float(1 + k));
        rels.push_back("images/e" + std::to_string(k) + ".exr");
        write_exr((dir / rels.back()).string(), m);
    }
    report::DataStore alone(dir, dir / "alone"), prepared(dir, dir / "prepared");
    prepared.prepare({rels[0], rels[1], rels[2], rels[3], rels[4], rels[1], "images/missing.exr", ""}, 3);
    for (int k : {3, 0, 1}) {
        const auto a = alone.image(rels[size_t(k)]), p = prepared.image(rels[size_t(k)]);
        ASSERT_TRUE(a && p) << rels[size_t(k)];
        EXPECT_EQ(p->key, a->key);
        EXPECT_EQ(p->auto_exposure, a->auto_exposure);
        EXPECT_EQ(p->p99, a->p99);
        EXPECT_EQ(p->max, a->max);
        EXPECT_EQ(testutil::read_text(dir / "prepared" / "data" / (p->key + ".js")),
                  testutil::read_text(dir / "alone" / "data" / (a->key + ".js")));
    }
    EXPECT_FALSE(prepared.image("images/missing.exr").has_value());
    EXPECT_EQ(prepared.files(), 3u);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir / "prepared" / "data"), fs::directory_iterator()), 3);
    fs::remove_all(dir);
}

// ---- what a failure says (verdict_text.h): the terminal and the card print the same lines ----

TEST(VerdictText, FailureSaysWhatWhereHowMuchAndHowToApprove) {
    auto& f = testutil::small_run();
    const json& t2 = f.results["tests"][1];
    const std::vector<std::string> lines = report::verdict_details(t2);
    const std::vector<std::string> want{
        "baseline: flip.mean 0.0123 > 0.01 (+0.0023)",
        "baseline: worst 16x16 block at (96,16) on metal r=0.3, mean FLIP 0.2",
        "reference: accuracy.flip.mean 0.052 outside",
        "reference: worst 16x16 block at (96,16) on metal r=0.3, mean FLIP 0.2",
        "golden made with Mesa 22.3.5, this run Mesa 22.3.6",
        "accuracy vs truth: 0.0300 -> 0.0520 (+73.3 %), band [0.0270, 0.0330]",
        "approve: iblcheck bless --suite ci --filter 'mobile.roughness_sweep.studio.dominant_dir=lagarde'"};
    EXPECT_EQ(lines, want);
    EXPECT_TRUE(report::verdict_details(f.results["tests"][0]).empty()) << "a pass prints no details";
    // An error prints its message; nothing to approve.
    const auto err = report::verdict_details(f.results["tests"][4]);
    ASSERT_EQ(err.size(), 1u);
    EXPECT_EQ(err[0], "shader compile failed: prefilter.glsl:12: 'foo' : undeclared identifier");
    // One line approves every failure (fail and missing-golden), globs joined by '|'.
    EXPECT_EQ(report::rebless_all_line(f.results["tests"], "ci"),
              "approve all 2 failures (after looking at them): iblcheck bless --suite 'ci' --filter "
              "'mobile.roughness_sweep.studio.dominant_dir=lagarde|mobile.furnace.constant'");
    EXPECT_EQ(report::rebless_all_line(json::array({f.results["tests"][0]}), "ci"), "");
}
} // namespace test_report_data
