// The HTML report (issues 8, 17): synthetic results with every verdict (tests/report_fixture.h),
// then plain parsing of index.html (order, bless command, chart points, escaping), the schema
// errors, the history file and what it flags, the float data scripts, the words a failure prints,
// and the `iblcheck report` command. The page in headless Chromium: test_report_browser.cpp.
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
#include <set>
#include <sstream>
#include <unistd.h>

#include "harness/cli/report_command.h"
#include "harness/common/errors.h"
#include "reports/drift.h"
#include "reports/float_data.h"
#include "reports/report_writer.h"
#include "reports/svg_chart.h"
#include "reports/verdict_text.h"
#include "tests/report_fixture.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;
using testutil::kEvilName;

namespace {

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
        const std::string body = html.substr(start, end - start);
        ChartInfo c{(*it)[1], std::stoi((*it)[2]),
                    int(count(body, "<circle class=\"point") + count(body, "<path class=\"point"))};
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
    auto& f = testutil::small_run();
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
    auto& f = testutil::small_run();
    const std::string html = slurp(f.out_dir / "index.html");
    const std::string fail = section_of(html, "mobile.roughness_sweep.studio.dominant_dir=lagarde");
    ASSERT_FALSE(fail.empty());
    EXPECT_NE(fail.find("<code>iblcheck bless --suite ci --filter &#39;mobile.roughness_sweep.studio.dominant_dir=lagarde"
                        "&#39;</code>"),
              std::string::npos);
    EXPECT_NE(fail.find("golden made with Mesa 22.3.5"), std::string::npos);
    EXPECT_NE(fail.find("differences may come from the platform"), std::string::npos);
    // The viewer knows the worst block and has its data (test, golden, FLIP map, sphere ids).
    EXPECT_NE(fail.find("data-bx=\"96\" data-by=\"16\""), std::string::npos);
    for (const char* k : {"data-test=\"", "data-golden=\"", "data-error=\"", "data-ids=\""})
        EXPECT_NE(fail.find(k), std::string::npos) << k;
    // What failed, in words: the check, where (sphere), the accuracy against the truth before -> after.
    EXPECT_NE(fail.find("baseline: flip.mean 0.0123 &gt; 0.01"), std::string::npos) << fail.substr(0, 3000);
    EXPECT_NE(fail.find("worst 16x16 block at (96,16) on metal r=0.3"), std::string::npos);
    EXPECT_NE(fail.find("accuracy vs truth: 0.0300 -&gt; 0.0520 (+73.3 %), band [0.0270, 0.0330]"), std::string::npos);
    const std::string missing = section_of(html, "mobile.furnace.constant");
    EXPECT_NE(missing.find("iblcheck bless"), std::string::npos);
    EXPECT_NE(missing.find("src=\"images/t4/test.png\""), std::string::npos);
    EXPECT_NE(missing.find("no golden to compare with yet"), std::string::npos);
    EXPECT_NE(missing.find("class=\"ev\""), std::string::npos) << "the rendering alone still gets its exposure control";
    EXPECT_EQ(section_of(html, "sampled.roughness_sweep.studio.samples=64").find("iblcheck bless"), std::string::npos);
    EXPECT_NE(html.find("image-rendering:pixelated"), std::string::npos);
    // Checks with tolerances and stability columns.
    EXPECT_NE(fail.find("<td class=\"st-fail\">fail</td>"), std::string::npos);
    EXPECT_NE(fail.find("25&times;"), std::string::npos);
    // History: the jump of the failing test's accuracy is flagged at its commit (beyond the floor: 0 here).
    EXPECT_NE(fail.find("accuracy moved +73.3 % at c4"), std::string::npos)
        << fail.substr(fail.find("History:") == std::string::npos ? 0 : fail.find("History:"), 600);
    // The summary says what changed since the baselines and approves every failure in one line.
    EXPECT_NE(html.find("<th>shader tree</th><td><span class=\"mono\">aaaa</span> (1 test)</td><td class=\"mono\">bbbb</td>"
                        "<td class=\"changed\">changed for 1 of 1</td>"),
              std::string::npos);
    EXPECT_NE(html.find("approve all 2 failures (after looking at them)</span><pre><code>iblcheck bless --suite &#39;ci&#39; "
                        "--filter &#39;mobile.roughness_sweep.studio.dominant_dir=lagarde|mobile.furnace.constant&#39;"),
              std::string::npos);
}

TEST(Report, ChartsAreSmallMultiplesOnTheStableCost) {
    auto& f = testutil::small_run();
    const std::string html = slurp(f.out_dir / "index.html");
    const auto cs = charts(html);
    for (auto& c : cs) EXPECT_EQ(c.declared, c.circles) << c.id;
    // Cost against accuracy, one panel per scene and environment, x = SPIR-V instructions per
    // pixel: roughness_sweep/studio has t1 (sampled, 54000), t2 (6300), t3 (6200) with both.
    EXPECT_EQ(declared_points(cs, "cost-accuracy-roughness-sweep-studio"), 3);
    EXPECT_NE(html.find("SPIR-V instructions executed per pixel (deterministic)"), std::string::npos);
    // t2 (6300, 0.052) is dominated by t3? No: t3 is cheaper (6200) but less accurate (0.061);
    // the front is t3, t2, t1.
    EXPECT_NE(html.find("class=\"pareto-front\" data-front=\"3\""), std::string::npos);
    // Wall time: median and range, no front; t1's range 24-70 ms is drawn.
    EXPECT_EQ(declared_points(cs, "wall-accuracy-roughness-sweep-studio"), 3);
    EXPECT_NE(html.find("median of 3, range 24\u201370 ms"), std::string::npos);
    {
        const size_t w = html.find("data-chart=\"wall-accuracy-roughness-sweep-studio\"");
        const std::string wall = html.substr(w, html.find("</svg>", w) - w);
        EXPECT_EQ(wall.find("pareto-front"), std::string::npos) << "wall time never carries the front";
        EXPECT_NE(wall.find("<line class=\"range\""), std::string::npos);
    }
    // Markers per variant family (dominant_dir and samples differ from the default's circle).
    EXPECT_NE(html.find("data-series=\"mobile \u00b7 dominant_dir\""), std::string::npos);
    EXPECT_NE(html.find("<path class=\"point\""), std::string::npos);
    // Error against roughness: one panel per family against the default (t2: dominant_dir), and the
    // sampled test's own panel.
    EXPECT_EQ(declared_points(cs, "error-roughness-roughness-sweep-studio-dominant-dir"), 8);
    EXPECT_EQ(declared_points(cs, "error-roughness-roughness-sweep-studio-sampled-samples"), 8);
    // Flicker against FLIP: one panel per environment; labels say what differs, the env included.
    EXPECT_EQ(declared_points(cs, "flicker-flip-rotation-sky-sun"), 2);
    EXPECT_NE(html.find("data-label=\"mobile temporal \u00b7 sky_sun\""), std::string::npos);
    // Texture memory against accuracy (issue 18's storage trade-off): t2 and t3 report their bytes;
    // bytes are deterministic, so the front is drawn (t3 is smaller, t2 more accurate: both on it).
    EXPECT_EQ(declared_points(cs, "bytes-accuracy-roughness-sweep-studio"), 2);
    {
        const size_t b = html.find("data-chart=\"bytes-accuracy-roughness-sweep-studio\"");
        ASSERT_NE(b, std::string::npos);
        const std::string chart = html.substr(b, html.find("</svg>", b) - b);
        EXPECT_NE(chart.find("class=\"pareto-front\" data-front=\"2\""), std::string::npos);
        EXPECT_NE(chart.find("131064 texels"), std::string::npos);
    }
    // Sparklines: 7 runs (6 stored + this one) for each test with that value.
    int spark = 0;
    for (auto& c : cs)
        if (c.id == "history-flip_mean") {
            ++spark;
            EXPECT_EQ(c.declared, 7);
        }
    EXPECT_EQ(spark, 6);
    EXPECT_NE(html.find("<title>mobile.roughness_sweep.studio.dominant_dir=lagarde\n6300 SPIR-V instructions/pixel"),
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
    auto& f = testutil::small_run();
    const std::string html = slurp(f.out_dir / "index.html");
    EXPECT_EQ(count(html, "<script>"), 2u) << "only the report's own scripts (its configuration and its code)";
    EXPECT_EQ(html.find("alert('x')"), std::string::npos);
    EXPECT_EQ(html.find("<b>bold</b>"), std::string::npos);
    EXPECT_NE(html.find("mobile.evil.&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;&amp;&quot;q&quot;"), std::string::npos);
    EXPECT_NE(html.find("&lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot;"), std::string::npos);
    EXPECT_EQ(report::html_escape("<a href=\"x\">'&'</a>"), "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
}

TEST(Report, SelfContainedImagesAndMissingOnes) {
    auto& f = testutil::small_run();
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
    // Every data script a viewer names is next to the page and holds what its meta says.
    std::regex dre("data-(test|golden|error|ids)=\"([0-9a-f]{16})\"");
    std::set<std::string> keys;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), dre); it != std::sregex_iterator(); ++it) keys.insert((*it)[2]);
    EXPECT_EQ(keys.size(), 4u) << "the nine tests share their pixels: one script each for test, golden, error map, ids";
    for (const std::string& k : keys) {
        const std::string js = slurp(f.out_dir / "data" / (k + ".js"));
        ASSERT_EQ(js.rfind("iblcheckData(\"" + k + "\",{", 0), 0u) << k;
        const json meta = json::parse(js.substr(js.find(',') + 1, js.find("},\"") - js.find(',')));
        const size_t q = js.find(",\"", js.find("},\"")) + 2;
        std::string b64 = js.substr(q, js.rfind('"') - q), bytes;
        for (size_t i = 0, acc = 0, bits = 0; i < b64.size(); ++i) { // base64 -> bytes
            const char ch = b64[i];
            const int v = ch >= 'A' && ch <= 'Z'   ? ch - 'A'
                          : ch >= 'a' && ch <= 'z' ? ch - 'a' + 26
                          : ch >= '0' && ch <= '9' ? ch - '0' + 52
                          : ch == '+'              ? 62
                          : ch == '/'              ? 63
                                                   : -1;
            if (v < 0) continue;
            acc = (acc << 6) | size_t(v);
            bits += 6;
            if (bits >= 8) bits -= 8, bytes += char((acc >> bits) & 0xff);
        }
        const size_t n_values = meta["w"].get<size_t>() * meta["h"].get<size_t>() * meta["c"].get<size_t>();
        EXPECT_EQ(report::unpack(bytes).size(), n_values * (meta["enc"] == "u8" ? 1 : 2)) << k;
    }
    // The grid's thumbnails are the renders at their automatic exposure, written beside the page.
    EXPECT_NE(html.find("<img class=\"thumb\" src=\"thumbs/"), std::string::npos);
    // Temporal: a filmstrip of the first 8 frames of each sequence, and a player over all 12.
    const std::string t6 = section_of(html, "mobile.rotation.sky_sun.temporal");
    EXPECT_EQ(count(t6, "class=\"frame\""), 16u);
    EXPECT_NE(t6.find("images/t6/frame011.png"), std::string::npos);

    // out_dir == results_dir: images stay where they are.
    report::write_report(f.results, f.results_dir, f.results_dir, {});
    EXPECT_TRUE(fs::exists(f.results_dir / "index.html"));
    EXPECT_TRUE(fs::exists(f.results_dir / "images/t1/test.png"));
}

// Results without float data (an older harness): the viewer is the PNGs side by side, no controls.
TEST(Report, ResultsWithoutEXRsShowThePNGs) {
    auto& f = testutil::small_run();
    json r = f.results;
    for (json& t : r["tests"]) {
        t.erase("image_exr");
        for (json& c : t["comparisons"])
            if (c.contains("images"))
                for (const char* k : {"test_exr", "golden_exr", "error_exr"}) c["images"].erase(k);
    }
    const fs::path out = f.root / "no_exr";
    report::write_report(r, f.results_dir, out);
    const std::string html = slurp(out / "index.html");
    EXPECT_EQ(html.find("data-test=\""), std::string::npos);
    EXPECT_EQ(html.find("class=\"ev\""), std::string::npos) << "no exposure control without float data";
    const std::string fail = section_of(html, "mobile.roughness_sweep.studio.dominant_dir=lagarde");
    EXPECT_NE(fail.find("<img class=\"gold\" src=\"images/t2/baseline.png\""), std::string::npos) << fail.substr(0, 4000);
    EXPECT_NE(fail.find("worst 16&times;16 block at (96,16)"), std::string::npos);
    EXPECT_FALSE(fs::exists(out / "data"));
}

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
    const std::string html = slurp(out / "index.html");
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
