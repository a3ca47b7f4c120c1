// The HTML report (issue 8): synthetic results with every verdict, images written with OpenCV,
// then plain parsing of index.html (order, bless command, chart points, escaping), the schema
// errors, the history file, the `iblcheck report` command, and a headless Chromium check that the
// page opens from file:// with no console error and every image loaded (plus a screenshot).
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "harness/cli/report_command.h"
#include "harness/common/errors.h"
#include "reports/report_writer.h"
#include "reports/svg_chart.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;

namespace {

const std::string kEvilName = "mobile.evil.<script>alert('x')</script>&\"q\"";

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

size_t count(const std::string& hay, const std::string& needle) {
    size_t n = 0;
    for (size_t p = hay.find(needle); p != std::string::npos; p = hay.find(needle, p + needle.size())) ++n;
    return n;
}

// A small "render": spheres-ish gradient with a seedable shift, 8-bit BGR.
cv::Mat fake_render(int w, int h, int shift) {
    cv::Mat m(h, w, CV_8UC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int cx = ((x / 48) * 48 + 24), cy = h / 2;
            const double d = std::hypot(x - cx, y - cy) / 20.0;
            const double v = d < 1 ? (1 - d * d) : 0.15;
            m.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(60 + 150 * v),
                                              cv::saturate_cast<uchar>(40 + 180 * v + shift),
                                              cv::saturate_cast<uchar>(30 + 200 * v * (x % 48) / 48.0 + shift));
        }
    return m;
}

cv::Mat fake_heatmap(int w, int h) {
    cv::Mat g(h, w, CV_8UC1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) g.at<uchar>(y, x) = cv::saturate_cast<uchar>(((x * 7 + y * 3) % 97) * 2);
    cv::Mat c;
    cv::applyColorMap(g, c, cv::COLORMAP_MAGMA);
    return c;
}

void write_png(const fs::path& root, const std::string& rel, const cv::Mat& m) {
    fs::create_directories((root / rel).parent_path());
    ASSERT_TRUE(cv::imwrite((root / rel).string(), m)) << rel;
}

json comparison(const std::string& kind, const std::string& dir, const std::string& verdict, double flip) {
    return json{
        {"kind", kind},
        {"golden", "goldens/" + kind + "/x.exr"},
        {"verdict", verdict},
        {"metrics",
         {{"flip", {{"mean", flip}, {"weighted_median", flip * 0.8}, {"p99", flip * 10}, {"max", 0.5},
                    {"block_max", 0.2}, {"block_x", 96}, {"block_y", 16}, {"mode", "hdr"}}},
          {"ssim", {{"mean", 0.99}}},
          {"psnr", {{"db", 41.2}, {"rmse", 0.01}, {"max_abs", 0.3}}}}},
        {"checks",
         json::array({{{"metric", "flip.mean"}, {"value", flip}, {"min", nullptr}, {"max", 0.01},
                       {"status", flip > 0.01 ? "fail" : "pass"}},
                      {{"metric", "ssim.mean"}, {"value", 0.99}, {"min", 0.98}, {"max", nullptr}, {"status", "pass"}}})},
        {"images",
         {{"test", "images/" + dir + "/test.png"},
          {"golden", "images/" + dir + "/" + kind + ".png"},
          {"heatmap", "images/" + dir + "/" + kind + "_flip.png"}}}};
}

json make_test(const std::string& method, const std::string& scene, const std::string& env, const std::string& variant,
               const std::string& verdict, const std::string& dir) {
    json t;
    t["name"] = method + "." + scene + "." + env + (variant.empty() ? "" : "." + variant);
    t["suite"] = "ci";
    t["scene"] = scene;
    t["method"] = method;
    t["env"] = env;
    t["variant"] = variant;
    t["options"] = json::object();
    if (!variant.empty()) {
        auto eq = variant.find('=');
        t["options"][variant.substr(0, eq)] = variant.substr(eq + 1);
    }
    t["width"] = 192;
    t["height"] = 48;
    t["verdict"] = verdict;
    t["message"] = verdict == "pass" ? "" : verdict + ": something";
    t["bless_command"] = "iblcheck bless --suite ci --filter '" + t["name"].get<std::string>() + "'";
    t["driver_mismatch"] = nullptr;
    t["comparisons"] = json::array({comparison("baseline", dir, verdict == "fail" ? "fail" : "pass",
                                               verdict == "fail" ? 0.0123 : 0.004)});
    t["timings"] = json::array({{{"pass", "prefilter_ggx"}, {"ms", 12.1}, {"gpu", true}, {"precompute", true}},
                                {{"pass", "shade_spheres"}, {"ms", 3.2}, {"gpu", true}, {"precompute", false}}});
    return t;
}

json per_sphere(double scale) {
    json a = json::array();
    for (double r : {0.1, 0.4, 0.7, 1.0}) {
        a.push_back({{"label", "metal r=" + std::to_string(r).substr(0, 3)}, {"roughness", r}, {"metallic", 1},
                     {"flip_mean", scale * (0.02 + r * 0.05)}});
        a.push_back({{"label", "plastic r=" + std::to_string(r).substr(0, 3)}, {"roughness", r}, {"metallic", 0},
                     {"flip_mean", scale * (0.01 + r * 0.03)}});
    }
    return a; // 8 spheres
}

struct Fixture {
    fs::path root, results_dir, out_dir;
    json results;
    std::vector<json> history;
};

// Builds the synthetic run once (images + results.json + history) and writes the report.
Fixture& fixture() {
    static Fixture f = [] {
        Fixture f;
        f.root = fs::temp_directory_path() / ("iblcheck_test_report_" + std::to_string(::getpid()));
        fs::remove_all(f.root);
        // Removed when the test process ends (set IBLCHECK_KEEP_TMP=1 to look at the report).
        static const fs::path cleanup = f.root;
        if (!std::getenv("IBLCHECK_KEEP_TMP"))
            std::atexit([] {
                std::error_code ec;
                fs::remove_all(cleanup, ec);
            });
        f.results_dir = f.root / "run";
        f.out_dir = f.root / "report";
        const int W = 192, H = 48;

        json tests = json::array();
        // Listed passes first on purpose: the report must put failures first.
        json t1 = make_test("sampled", "roughness_sweep", "studio", "samples=64", "pass", "t1");
        t1["accuracy"] = {{"flip_mean", 0.011}, {"golden", "goldens/reference/roughness_sweep__studio.exr"}};
        t1["frame_ms"] = 31.0;
        t1["precompute_ms"] = 4.0;
        t1["texture_fetches_per_pixel"] = 64;
        t1["per_sphere"] = per_sphere(0.3);
        tests.push_back(t1);

        json t2 = make_test("mobile", "roughness_sweep", "studio", "dominant_dir=lagarde", "fail", "t2");
        t2["message"] = "baseline: flip.mean 0.0123 > 0.0100 (+0.0023); worst 16x16 block at (96,16)";
        t2["driver_mismatch"] = "golden made with Mesa 22.3.5, this run Mesa 22.3.6";
        t2["accuracy"] = {{"flip_mean", 0.052}, {"golden", "goldens/reference/roughness_sweep__studio.exr"}};
        t2["frame_ms"] = 3.2;
        t2["precompute_ms"] = 40.1;
        t2["texture_fetches_per_pixel"] = 2.5;
        t2["per_sphere"] = per_sphere(1.0);
        t2["stability"] = {{"noise_floor", {{"flip.mean", 0.0004}}}, {"margins", {{"flip.mean", 25.0}}}, {"flaky", false}};
        tests.push_back(t2);

        json t3 = make_test("mobile", "roughness_sweep", "studio", "dominant_dir=none", "improved", "t3");
        t3["accuracy"] = {{"flip_mean", 0.061}};
        t3["frame_ms"] = 3.0;
        t3["precompute_ms"] = 38.0;
        t3["texture_fetches_per_pixel"] = 2.0;
        tests.push_back(t3);

        json t4 = make_test("mobile", "furnace", "constant", "", "missing-golden", "t4");
        t4["comparisons"] = json::array(); // no golden: nothing to compare, the rendering alone
        t4["image"] = "images/t4/test.png";
        tests.push_back(t4);

        json t5 = make_test("sampled", "broken", "sky_sun", "", "error", "t5");
        t5["message"] = "shader compile failed: prefilter.glsl:12: 'foo' : undeclared identifier";
        t5["comparisons"] = json::array();
        t5["accuracy"] = nullptr;
        tests.push_back(t5);

        json t6 = make_test("mobile", "rotation", "sky_sun", "temporal", "pass", "t6");
        t6["options"] = json::object();
        t6["accuracy"] = {{"flip_mean", 0.03}};
        t6["frame_ms"] = 3.5;
        t6["precompute_ms"] = 41.0;
        t6["texture_fetches_per_pixel"] = 2.5;
        t6["temporal"] = {{"frames", json::array()}, {"reference_frames", json::array()}, {"flicker", 0.01},
                          {"variation_ratio", 1.3}, {"flip_mean", 0.02}};
        for (int i = 0; i < 12; ++i) {
            t6["temporal"]["frames"].push_back(fmt::format("images/t6/frame{:03d}.png", i));
            t6["temporal"]["reference_frames"].push_back(fmt::format("images/t6/ref{:03d}.png", i));
        }
        tests.push_back(t6);

        json t7 = make_test("sampled", "rotation", "sky_sun", "temporal", "pass", "t7");
        t7["options"] = json::object();
        t7["accuracy"] = {{"flip_mean", 0.014}};
        t7["frame_ms"] = 28.0;
        t7["precompute_ms"] = 3.0;
        t7["texture_fetches_per_pixel"] = 64;
        t7["temporal"] = {{"frames", t6["temporal"]["frames"]}, {"flicker", 0.004}, {"flip_mean", 0.012}};
        tests.push_back(t7);

        json t8 = make_test("mobile", "evil", "studio", "", "pass", "evil");
        t8["name"] = kEvilName;
        t8["message"] = "<b>bold</b> & \"quoted\"";
        t8["accuracy"] = {{"flip_mean", 0.08}};
        t8["frame_ms"] = 2.0;
        tests.push_back(t8);

        json t9 = make_test("reference", "roughness_sweep", "studio", "", "pass", "t9");
        t9["comparisons"][0]["images"]["heatmap"] = "images/t9/does_not_exist.png"; // a placeholder, not an error
        t9["frame_ms"] = 5000.0;
        tests.push_back(t9);

        f.results = {{"schema", "iblcheck-results/1"},
                     {"suite", "ci"},
                     {"command", "iblcheck run --suite ci --out report"},
                     {"started", "2026-11-22T15:40:00Z"},
                     {"total_s", 41.2},
                     {"commit", "f554dd9"},
                     {"dirty", true},
                     {"driver",
                      {{"device", "llvmpipe (LLVM 15.0.6, 256 bits)"}, {"driver", "llvmpipe"},
                       {"driver_info", "Mesa 22.3.6 (LLVM 15.0.6)"}, {"mesa", "22.3.6"}, {"llvm", "15.0.6"},
                       {"api", "1.3.230"}}},
                     {"counts", {{"pass", 5}, {"fail", 1}, {"improved", 1}, {"missing-golden", 1}, {"error", 1}}},
                     {"tests", tests}};

        // Images.
        for (const char* d : {"t1", "t2", "t3", "t4", "t5", "t6", "t7", "evil", "t9"}) {
            write_png(f.results_dir, std::string("images/") + d + "/test.png", fake_render(W, H, 0));
            write_png(f.results_dir, std::string("images/") + d + "/baseline.png", fake_render(W, H, 25));
            write_png(f.results_dir, std::string("images/") + d + "/baseline_flip.png", fake_heatmap(W, H));
        }
        for (int i = 0; i < 12; ++i) {
            cv::Mat fr = fake_render(96, 48, 0), rf = fake_render(96, 48, 0);
            cv::circle(fr, {20 + 5 * i, 24}, 6, cv::Scalar(255, 255, 255), -1);
            cv::circle(rf, {20 + 5 * i, 24}, 6, cv::Scalar(230, 240, 255), -1);
            if (i % 3 == 1) fr *= 1.15; // flicker
            write_png(f.results_dir, fmt::format("images/t6/frame{:03d}.png", i), fr);
            write_png(f.results_dir, fmt::format("images/t6/ref{:03d}.png", i), rf);
        }
        {
            std::ofstream(f.results_dir / "results.json") << f.results.dump(2);
        }

        // History: 6 older runs; the failing test's accuracy jumped at c4.
        for (int i = 0; i < 6; ++i) {
            json h = report::history_entry(f.results);
            h["commit"] = fmt::format("c{}", i);
            h["date"] = fmt::format("2026-11-{:02d}T03:00:00Z", 10 + i);
            h["dirty"] = false;
            for (auto& [name, v] : h["tests"].items()) {
                if (v.contains("flip_mean")) v["flip_mean"] = v["flip_mean"].get<double>() * (1 + 0.01 * (i % 2));
                if (v.contains("frame_ms")) v["frame_ms"] = v["frame_ms"].get<double>() * (1 + 0.02 * (i % 3));
            }
            h["tests"][t2["name"].get<std::string>()]["flip_mean"] = i < 4 ? 0.030 : 0.052;
            h["tests"][t2["name"].get<std::string>()]["verdict"] = i < 4 ? "pass" : "fail";
            report::append_history(f.root / "history.jsonl", h);
        }
        f.history = report::read_history(f.root / "history.jsonl");
        report::write_report(f.results, f.results_dir, f.out_dir, f.history);
        return f;
    }();
    return f;
}

std::string section_of(const std::string& html, const std::string& escaped_name) {
    const std::string key = "data-name=\"" + escaped_name + "\" data-verdict";
    size_t p = html.find("<section class=\"test");
    while (p != std::string::npos) {
        const size_t end = html.find("</section>", p);
        const std::string s = html.substr(p, end - p);
        if (s.find(key) != std::string::npos) return s;
        p = html.find("<section class=\"test", end);
    }
    return "";
}

// Every <svg class="chart..." data-chart="ID" data-points="N"> with its number of circle.point.
struct ChartInfo {
    std::string id;
    int declared = 0, circles = 0;
};
std::vector<ChartInfo> charts(const std::string& html) {
    std::vector<ChartInfo> out;
    std::regex re("<svg class=\"chart[^\"]*\" data-chart=\"([^\"]+)\"[^>]*data-points=\"(\\d+)\"");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it) {
        const size_t start = size_t(it->position(0));
        const size_t end = html.find("</svg>", start);
        ChartInfo c{(*it)[1], std::stoi((*it)[2]), int(count(html.substr(start, end - start), "<circle class=\"point"))};
        out.push_back(c);
    }
    return out;
}

int declared_points(const std::vector<ChartInfo>& cs, const std::string& id) {
    for (auto& c : cs)
        if (c.id == id) return c.declared;
    return -1;
}

} // namespace

TEST(Report, FailuresFirstInOrderOfSeverity) {
    auto& f = fixture();
    const std::string html = slurp(f.out_dir / "index.html");
    std::regex re("<section class=\"test s-([a-z-]+) ");
    std::vector<std::string> order;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it)
        order.push_back((*it)[1]);
    ASSERT_EQ(order.size(), 9u);
    const std::vector<std::string> want{"fail", "error", "missing-golden", "improved", "pass", "pass", "pass", "pass", "pass"};
    EXPECT_EQ(order, want);
    // The overview table too: the failing test's row comes before the first passing one.
    EXPECT_LT(html.find("data-name=\"mobile.roughness_sweep.studio.dominant_dir=lagarde\""),
              html.find("data-name=\"sampled.roughness_sweep.studio.samples=64\""));
    // Summary: counts and environment.
    EXPECT_NE(html.find("data-verdict=\"fail\" data-count=\"1\""), std::string::npos);
    EXPECT_NE(html.find("data-verdict=\"pass\" data-count=\"5\""), std::string::npos);
    for (const char* s : {"f554dd9", "dirty", "llvmpipe (LLVM 15.0.6, 256 bits)", "22.3.6", "15.0.6", "41.2 s",
                          "iblcheck run --suite ci --out report"})
        EXPECT_NE(html.find(s), std::string::npos) << s;
}

TEST(Report, BlessCommandOnlyWhereNeeded) {
    auto& f = fixture();
    const std::string html = slurp(f.out_dir / "index.html");
    const std::string fail = section_of(html, "mobile.roughness_sweep.studio.dominant_dir=lagarde");
    ASSERT_FALSE(fail.empty());
    EXPECT_NE(fail.find("<code>iblcheck bless --suite ci --filter &#39;mobile.roughness_sweep.studio.dominant_dir=lagarde"
                        "&#39;</code>"),
              std::string::npos);
    EXPECT_NE(fail.find("golden made with Mesa 22.3.5"), std::string::npos);
    EXPECT_NE(fail.find("differences may come from the platform"), std::string::npos);
    EXPECT_NE(fail.find("class=\"blk\" style=\"left:96px;top:16px\""), std::string::npos);
    const std::string missing = section_of(html, "mobile.furnace.constant");
    EXPECT_NE(missing.find("iblcheck bless"), std::string::npos);
    EXPECT_NE(missing.find("src=\"images/t4/test.png\""), std::string::npos);
    EXPECT_NE(missing.find("no golden to compare with yet"), std::string::npos);
    EXPECT_EQ(section_of(html, "sampled.roughness_sweep.studio.samples=64").find("iblcheck bless"), std::string::npos);
    EXPECT_NE(html.find("image-rendering:pixelated"), std::string::npos);
    // Checks with tolerances and stability columns.
    EXPECT_NE(fail.find("<td class=\"st-fail\">fail</td>"), std::string::npos);
    EXPECT_NE(fail.find("25&times;"), std::string::npos);
    // History: the jump of the failing test's accuracy is labelled with its commit.
    EXPECT_NE(fail.find("FLIP moved +73% at c4"), std::string::npos) << fail.substr(fail.find("History:") == std::string::npos ? 0 : fail.find("History:"), 600);
}

TEST(Report, ChartsHaveOnePointPerTest) {
    auto& f = fixture();
    const std::string html = slurp(f.out_dir / "index.html");
    const auto cs = charts(html);
    for (auto& c : cs) EXPECT_EQ(c.declared, c.circles) << c.id;
    // accuracy + frame_ms: t1 t2 t3 t6 t7 evil (t9 has no accuracy).
    EXPECT_EQ(declared_points(cs, "speed-accuracy"), 6);
    EXPECT_EQ(declared_points(cs, "speed-accuracy-precompute"), 5);
    EXPECT_EQ(declared_points(cs, "speed-accuracy-fetches"), 5);
    EXPECT_EQ(declared_points(cs, "error-roughness"), 16);
    EXPECT_EQ(declared_points(cs, "flicker-flip"), 2);
    // Sparklines: 7 runs (6 stored + this one) for each test with that value.
    int spark = 0;
    for (auto& c : cs)
        if (c.id == "history-flip_mean") {
            ++spark;
            EXPECT_EQ(c.declared, 7);
        }
    EXPECT_EQ(spark, 6);
    // The Pareto front over (frame_ms, flip): evil (2.0, 0.08), t3 (3.0, 0.061), t2 (3.2, 0.052),
    // t6 (3.5, 0.03), t7 (28, 0.014), t1 (31, 0.011): all six are on it.
    EXPECT_NE(html.find("class=\"pareto-front\" data-front=\"6\""), std::string::npos);
    // Legend, tick labels, tooltips.
    EXPECT_NE(html.find("Pareto front (lower-left is better)"), std::string::npos);
    EXPECT_NE(html.find("frame time, ms (log scale)"), std::string::npos);
    EXPECT_NE(html.find("<title>mobile.roughness_sweep.studio.dominant_dir=lagarde\nscene roughness_sweep"),
              std::string::npos);
}

TEST(Report, ParetoFront) {
    using report::pareto_front;
    // (1,5) (2,2) (3,3: dominated by (2,2)) (4,1) (4,1: duplicate, both kept) (5,0.5)
    std::vector<std::pair<double, double>> p{{1, 5}, {2, 2}, {3, 3}, {4, 1}, {4, 1}, {5, 0.5}};
    EXPECT_EQ(pareto_front(p), (std::vector<size_t>{0, 1, 3, 4, 5}));
    EXPECT_TRUE(pareto_front({}).empty());
}

TEST(Report, EscapesEveryString) {
    auto& f = fixture();
    const std::string html = slurp(f.out_dir / "index.html");
    EXPECT_EQ(count(html, "<script>"), 1u) << "only the report's own script";
    EXPECT_EQ(html.find("alert('x')"), std::string::npos);
    EXPECT_EQ(html.find("<b>bold</b>"), std::string::npos);
    EXPECT_NE(html.find("mobile.evil.&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;&amp;&quot;q&quot;"), std::string::npos);
    EXPECT_NE(html.find("&lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot;"), std::string::npos);
    EXPECT_EQ(report::html_escape("<a href=\"x\">'&'</a>"), "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
}

TEST(Report, SelfContainedImagesAndMissingOnes) {
    auto& f = fixture();
    const std::string html = slurp(f.out_dir / "index.html");
    EXPECT_TRUE(fs::exists(f.out_dir / "images/t2/baseline_flip.png"));
    EXPECT_TRUE(fs::exists(f.out_dir / "images/t6/frame011.png"));
    EXPECT_TRUE(fs::exists(f.out_dir / "images/t6/ref011.png"));
    EXPECT_NE(html.find("missing image:"), std::string::npos);
    EXPECT_NE(html.find("images/t9/does_not_exist.png"), std::string::npos);
    // Every <img src> in the page exists next to it (relative, inside out_dir).
    std::regex re("<img [^>]*src=\"([^\"]+)\"");
    int n = 0;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it, ++n) {
        std::string src = (*it)[1];
        EXPECT_EQ(src.find(".."), std::string::npos) << src;
        EXPECT_TRUE(fs::exists(f.out_dir / src)) << src;
    }
    EXPECT_GT(n, 40);
    // Temporal: a filmstrip of the first 8 frames of each sequence, and a player over all 12.
    const std::string t6 = section_of(html, "mobile.rotation.sky_sun.temporal");
    EXPECT_EQ(count(t6, "class=\"frame\""), 16u);
    EXPECT_NE(t6.find("images/t6/frame011.png"), std::string::npos);

    // out_dir == results_dir: images stay where they are.
    report::write_report(f.results, f.results_dir, f.results_dir, {});
    EXPECT_TRUE(fs::exists(f.results_dir / "index.html"));
    EXPECT_TRUE(fs::exists(f.results_dir / "images/t1/test.png"));
}

TEST(Report, MalformedResultsNameFileAndProblem) {
    auto& f = fixture();
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
    auto& f = fixture();
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
    auto& f = fixture();
    const fs::path out = f.root / "cli_out";
    CLI::App app;
    int exit_code = -1;
    cli::register_report_command(app, exit_code);
    const std::string res = (f.results_dir / "results.json").string(), o = out.string(),
                      h = (f.root / "history.jsonl").string();
    std::vector<std::string> args{h, "--history", o, "--out", res, "report"}; // CLI11 wants them reversed
    app.parse(args);
    EXPECT_EQ(exit_code, 0);
    const std::string html = slurp(out / "index.html");
    EXPECT_NE(html.find("data-chart=\"history-flip_mean\""), std::string::npos);
    EXPECT_TRUE(fs::exists(out / "images/t2/test.png"));
}

// ---- headless Chromium: the page opens from file://, no console error, every image loads ----

namespace {
const char* kChromium = "/usr/bin/chromium";

int run_chromium(const fs::path& profile, const std::string& extra, const fs::path& html, const fs::path& out,
                 const fs::path& err) {
    const std::string cmd = fmt::format(
        "timeout 60 {} --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
        "--disable-background-networking --disable-component-update --disable-sync --user-data-dir='{}' "
        "--virtual-time-budget=5000 --enable-logging=stderr --v=0 {} 'file://{}' >'{}' 2>'{}'",
        kChromium, profile.string(), extra, html.string(), out.string(), err.string());
    return std::system(cmd.c_str());
}

std::string attr(const std::string& tag, const std::string& name) {
    std::smatch m;
    if (std::regex_search(tag, m, std::regex(name + "=\"([^\"]*)\""))) return m[1];
    return "";
}
} // namespace

TEST(ReportBrowser, OpensOfflineWithEveryImageLoaded) {
    if (!fs::exists(kChromium)) GTEST_SKIP() << kChromium << " is not installed (Debian package chromium): "
                                             << "the headless check of the report is skipped";
    auto& f = fixture();
    const fs::path html = fs::absolute(f.out_dir / "index.html");
    const fs::path dom = f.root / "dom.html", err = f.root / "chromium.stderr";
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = run_chromium(f.root / "profile1", "--dump-dom", html, dom, err);
    ASSERT_EQ(rc, 0) << slurp(err);
    const std::string d = slurp(dom), log = slurp(err);

    // No console error from the page.
    std::istringstream ls(log);
    for (std::string line; std::getline(ls, line);)
        if (line.find("CONSOLE") != std::string::npos &&
            (line.find("Uncaught") != std::string::npos || line.find("rror") != std::string::npos ||
             line.find("Failed to load") != std::string::npos))
            ADD_FAILURE() << "console: " << line;

    std::smatch m;
    ASSERT_TRUE(std::regex_search(d, m, std::regex("<body[^>]*>"))) << d.substr(0, 2000);
    const std::string body = m[0];
    ASSERT_EQ(attr(body, "data-check"), "done") << "the page's load check did not run: " << body;
    const std::string source = slurp(html);
    const size_t img_tags = count(source, "<img ");
    EXPECT_EQ(attr(body, "data-images-total"), std::to_string(img_tags)) << body;
    EXPECT_EQ(attr(body, "data-images-failed"), "0") << attr(body, "data-images-failed-src");
    EXPECT_EQ(attr(body, "data-chart-points"), attr(body, "data-chart-points-declared")) << body;
    int declared = 0;
    for (auto& c : charts(source)) declared += c.declared;
    EXPECT_EQ(attr(body, "data-chart-points"), std::to_string(declared)) << body;
    EXPECT_EQ(attr(body, "data-tests"), "9");
    // The filter script ran (it writes the count line).
    EXPECT_NE(d.find("9 of 9 tests shown"), std::string::npos);

    // Screenshot, kept in the build folder for people to look at.
    const fs::path shot = fs::path(IBLCHECK_BINARY_DIR) / "report_screenshot.png";
    fs::remove(shot);
    const int rc2 = run_chromium(f.root / "profile2",
                                 fmt::format("--hide-scrollbars --window-size=1400,2000 --screenshot='{}'", shot.string()),
                                 html, f.root / "shot.stdout", f.root / "shot.stderr");
    ASSERT_EQ(rc2, 0) << slurp(f.root / "shot.stderr");
    ASSERT_TRUE(fs::exists(shot)) << slurp(f.root / "shot.stderr");
    EXPECT_GT(fs::file_size(shot), 30000u);
    cv::Mat img = cv::imread(shot.string());
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.cols, 1400);
    EXPECT_EQ(img.rows, 2000);
    cv::Scalar mean, stddev;
    cv::meanStdDev(img, mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30.0) << "the screenshot looks blank";
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(secs, 30.0);
    std::cout << "screenshot: " << shot.string() << " (" << secs << " s for both Chromium runs)\n";
}
