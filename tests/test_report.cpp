// The HTML report's page (issues 8, 17): synthetic results with every verdict
// (tests/report_fixture.h), then plain parsing of index.html: order, bless command, chart points,
// escaping, the images it copies and the ones it lacks. What the page is built from (the results
// schema, the history, the float data, the words of a failure, `iblcheck report`):
// test_report_data.cpp. The page in headless Chromium: test_report_browser.cpp.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "kernel/name_filter.h"
#include "reports/float_data.h"
#include "reports/report_writer.h"
#include "reports/svg_chart.h"
#include "tests/report_fixture.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;
using testutil::kEvilName;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report {

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
    // The variant's white-furnace figure (issue 27), per roughness, in percent.
    EXPECT_NE(fail.find("white furnace (energy against the exact albedo, F0 = 1): r = 0.25: -13.0 %, r = 0.5: -18.0 %, "
                        "r = 0.75: -8.8 %, r = 1: +16.5 %"),
              std::string::npos);
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
    // The run was the whole suite: globs that select exactly the failures, not their names spelt out (issue 32).
    std::smatch m;
    ASSERT_TRUE(std::regex_search(html, m,
                                  std::regex("approve all 2 failures \\(after looking at them\\)</span><pre><code>iblcheck bless "
                                             "--suite &#39;ci&#39; --filter &#39;([^&]+)&#39;</code>")));
    for (const json& t : f.results["tests"])
        EXPECT_EQ(name_filter_match(m[1], t["name"]), t["verdict"] == "fail" || t["verdict"] == "missing-golden")
            << m[1] << " and " << t["name"];
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
// A test's card says whose renders its frame time pools (harness/timing_groups.h): the group's
// pattern, escaped, after the count; a test timed alone says only the count.
TEST(Report, TheCardNamesTheTimingGroupItsFrameTimePools) {
    auto& f = testutil::small_run();
    json r = f.results;
    for (json& t : r["tests"])
        if (t["name"] == "sampled.roughness_sweep.studio.samples=64")
            t["timing_group"] = "sampled.roughness_sweep.*.<samples=64>";
    const fs::path out = f.root / "timing_group";
    report::write_report(r, f.results_dir, out);
    const std::string card = section_of(slurp(out / "index.html"), "sampled.roughness_sweep.studio.samples=64");
    ASSERT_FALSE(card.empty());
    EXPECT_NE(
        card.find("frame <b>31 ms</b> (median of 3 renders of <span class=\"mono\">sampled.roughness_sweep.*.&lt;samples=64&gt;"
                  "</span>, range 24&ndash;70)"),
        std::string::npos)
        << card.substr(0, 6000);
    const std::string alone = section_of(slurp(f.out_dir / "index.html"), "sampled.roughness_sweep.studio.samples=64");
    EXPECT_NE(alone.find("frame <b>31 ms</b> (median of 3, range 24&ndash;70)"), std::string::npos);
}
} // namespace test_report
