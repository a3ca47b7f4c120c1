// The report in headless Chromium (tests/browser.h: the DevTools protocol over a pipe): the page
// opens from file:// with no error logged, every image and data script loads, and a person's use
// works: a ci report with one failure shows the failure, its images at a readable size, its
// exposure control and its bless command in the first screen and stays under 4,000 px; the
// exposure slider redraws the float data (exposure 0 equals the harness's display transform),
// zoom keeps pixels square, the pointer names the sphere, the magnifier follows it, the mask counts
// the pixels over the tolerance, a passing tile opens its card. Skipped without /usr/bin/chromium.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <fstream>

#include "metrics/display_transform.h"
#include "reports/report_writer.h"
#include "tests/browser.h"
#include "tests/report_fixture.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;
using testutil::Browser;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report_browser {

namespace {

const char* kReady = "document.body && document.body.getAttribute('data-check') === 'done'";

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

size_t count(const std::string& hay, const std::string& needle) {
    size_t n = 0;
    for (size_t p = hay.find(needle); p != std::string::npos; p = hay.find(needle, p + needle.size())) ++n;
    return n;
}

std::string body(Browser& b, const char* attr) {
    return b.eval(fmt::format("document.body.getAttribute('{}')", attr)).get<std::string>();
}

void expect_loaded(Browser& b) {
    EXPECT_EQ(body(b, "data-images-failed"), "0") << body(b, "data-images-failed-src");
    EXPECT_EQ(body(b, "data-data-failed"), "0") << body(b, "data-data-failed-keys");
    EXPECT_EQ(body(b, "data-viewers-failed"), "0");
    EXPECT_EQ(body(b, "data-chart-points"), body(b, "data-chart-points-declared"));
}

void save(const std::string& png, const std::string& name) {
    const fs::path shot = fs::path(IBLCHECK_BINARY_DIR) / name;
    std::ofstream(shot, std::ios::binary) << png;
    std::cout << "screenshot: " << shot.string() << "\n";
}

} // namespace

TEST(ReportBrowser, OpensOfflineWithEveryImageAndDataScriptLoaded) {
    if (!Browser::available()) GTEST_SKIP() << Browser::kChromium << " is not installed (Debian package chromium)";
    auto& f = testutil::small_run();
    const fs::path html = fs::absolute(f.out_dir / "index.html");
    const fs::path profile = testutil::temp_dir("browser_small");
    {
        Browser b(profile, 1400, 1000);
        b.open("file://" + html.string(), kReady);
        expect_loaded(b);
        const std::string source = slurp(html);
        EXPECT_EQ(body(b, "data-images-total"), std::to_string(count(source, "<img ")));
        EXPECT_EQ(body(b, "data-tests"), "9");
        // Every viewer shown from the start (the cards that need a look) has drawn its data.
        const int shown = b.eval("document.querySelectorAll('section.test:not([hidden]) .cmp:not([hidden]) "
                                 ".viewer[data-test], section.test:not([hidden]) > .viewer[data-test]').length")
                              .get<int>();
        EXPECT_GE(shown, 3);
        EXPECT_EQ(body(b, "data-viewers-ready"), std::to_string(shown));
        EXPECT_NE(b.eval("document.getElementById('filter-count').textContent").get<std::string>().find("9 of 9 tests shown"),
                  std::string::npos);
        // The tabs: Charts shows the charts and hides the tests.
        auto [cx, cy] = b.centre_of("nav.tabs a[href='#charts']");
        b.click(cx, cy);
        ASSERT_TRUE(b.wait_for("!document.getElementById('tab-charts').hidden && document.getElementById('tab-tests').hidden"));
        EXPECT_GT(b.eval("document.querySelectorAll('#tab-charts svg.chart').length").get<int>(), 5);
        save(b.screenshot(false), "report_screenshot.png");
        for (const std::string& e : b.errors()) ADD_FAILURE() << "page: " << e;
    }
    fs::remove_all(profile);
}

// One headless-browser session that steps through the page as a reader does (first screen, the failing
// card, its viewer, the tabs): ~110 lines on purpose, each step needs the page state the one before left.
TEST(ReportBrowser, CiReportWithOneFailureReadsInTheFirstScreenAndItsViewerWorks) {
    if (!Browser::available()) GTEST_SKIP() << Browser::kChromium << " is not installed (Debian package chromium)";
    const fs::path dir = testutil::temp_dir("browser_ci");
    const testutil::CiRun run = testutil::make_ci_run(dir / "run", 31, true);
    report::write_report(run.results, run.dir, run.dir);
    {
        Browser b(dir / "profile", 1440, 900);
        b.open("file://" + (run.dir / "index.html").string(), kReady);
        expect_loaded(b);
        EXPECT_EQ(body(b, "data-viewers-ready"), "1");

        // The whole page: a ci run of 31 passes and one failure is a few screens, not 50,000 px.
        const int height = b.eval("document.documentElement.scrollHeight").get<int>();
        std::cout << "ci report (31 pass, 1 fail) at 1440x900: " << height << " px\n";
        EXPECT_LT(height, 4000);
        // The first screen: the failure, its bless command, its exposure control, its image at 2x or more.
        const std::string card = "section.test.s-fail";
        auto bottom = [&](const std::string& sel) {
            return b.eval("document.querySelector(" + json(sel).dump() + ").getBoundingClientRect().bottom").get<double>();
        };
        EXPECT_LE(bottom(card + " .cmd.bless"), 900);
        EXPECT_LE(bottom(card + " input.ev"), 900);
        EXPECT_LE(b.eval("document.querySelector('" + card + " canvas.cv-img').getBoundingClientRect().top").get<double>() + 100,
                  900);
        const int zoom =
            std::stoi(b.eval("document.querySelector('" + card + " .viewer').getAttribute('data-zoom')").get<std::string>());
        EXPECT_GE(zoom, 2);
        EXPECT_EQ(b.eval("document.querySelector('" + card + " canvas.cv-img').style.width").get<std::string>(),
                  std::to_string(run.width * zoom) + "px");

        // Exposure 0 is the harness's display transform of the float data (the PNG, without its banding).
        auto pixel = [&](int x, int y) {
            return b.eval(fmt::format("Array.from(document.querySelector('{} canvas.cv-img').getContext('2d')"
                                      ".getImageData({},{},1,1).data)",
                                      card, x, y));
        };
        auto click = [&](const std::string& sel) {
            auto [x, y] = b.centre_of(sel);
            b.click(x, y);
        };
        click(card + " button.ev-0");
        const int px = 24 + 48 * 2, py = 24; // metal r=0.2, its centre
        json p0 = pixel(px, py);
        const cv::Vec3f lin = run.failing_test.at<cv::Vec3f>(py, px);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(p0[c].get<int>(), int(display_transform_channel(lin[c]) * 255.0f + 0.5f), 1) << "channel " << c;
        // The slider, moved by the mouse: +EV brightens the same pixel; the readout says so.
        auto [sx, sy] = b.centre_of(card + " input.ev");
        const double sw = b.eval("document.querySelector('" + card + " input.ev').getBoundingClientRect().width").get<double>();
        b.click(sx + 0.25 * sw, sy); // from its centre: -12..+12 EV, so about +6 EV
        const std::string ev = b.eval("document.querySelector('" + card + " output.evv').textContent").get<std::string>();
        EXPECT_EQ(ev.rfind("+", 0), 0u) << ev;
        json p1 = pixel(px, py);
        EXPECT_GT(p1[1].get<int>(), p0[1].get<int>() + 20) << p0.dump() << " -> " << p1.dump();
        // auto: back to the image's automatic exposure.
        click(card + " button.ev-auto");
        EXPECT_NE(b.eval("document.querySelector('" + card + " output.evv').textContent").get<std::string>().find("(auto)"),
                  std::string::npos);

        // Zoom 4x: nearest-neighbour pixels, the worst block's outline scaled with it.
        click(card + " button.z[data-z='4']");
        EXPECT_EQ(b.eval("document.querySelector('" + card + " canvas.cv-img').style.width").get<std::string>(),
                  std::to_string(run.width * 4) + "px");
        EXPECT_EQ(
            b.eval("getComputedStyle(document.querySelector('" + card + " canvas.cv-img')).imageRendering").get<std::string>(),
            "pixelated");
        EXPECT_EQ(b.eval("document.querySelector('" + card + " .vimg .blk').style.left").get<std::string>(), "960px");

        // The pointer names the sphere under it and the magnifier follows it.
        const json r = b.eval("(function(){var c=document.querySelector('" + card +
                              " canvas.cv-img');c.scrollIntoView({block:'center'});var b=c.getBoundingClientRect();"
                              "return [b.left,b.top];})()");
        const int hx = 24 + 48 * 3, hy = 20; // metal r=0.3
        b.mouse_move(r[0].get<double>() + (hx + 0.5) * 4, r[1].get<double>() + (hy + 0.5) * 4);
        const std::string readout = b.eval("document.querySelector('" + card + " .readout').textContent").get<std::string>();
        EXPECT_EQ(readout.rfind(fmt::format("({},{}) metal r=0.3 \u00b7 roughness 0.3, metallic 1", hx, hy), 0), 0u) << readout;
        EXPECT_EQ(b.eval("document.querySelector('" + card + " .vimg .ptr').textContent").get<std::string>(), "metal r=0.3");
        EXPECT_NE(b.eval("document.querySelector('" + card + " .mcap').textContent")
                      .get<std::string>()
                      .find(fmt::format("around ({},{}) on metal r=0.3", hx, hy)),
                  std::string::npos);
        const json mg = b.eval("Array.from(document.querySelector('" + card +
                               " canvas.mg-t').getContext('2d').getImageData(72,72,1,1).data)");
        EXPECT_GT(mg[0].get<int>() + mg[1].get<int>() + mg[2].get<int>(), 30) << "the magnifier drew the sphere";

        // The heatmap's colour bar has its scale; the mask counts the pixels over the tolerance.
        EXPECT_EQ(b.eval("Array.from(document.querySelectorAll('" + card + " .cbar .tk')).pop().textContent").get<std::string>(),
                  "0.5");
        click(card + " input.mask");
        const std::string mask = b.eval("document.querySelector('" + card + " .maskinfo').textContent").get<std::string>();
        EXPECT_EQ(mask.rfind(std::to_string(run.pixels_over_002) + " px (", 0), 0u) << mask;
        EXPECT_GT(run.pixels_over_002, 500);
        const json masked = b.eval(fmt::format("Array.from(document.querySelector('{} canvas.cv-err').getContext('2d')"
                                               ".getImageData({},{},1,1).data)",
                                               card, 24 + 48 * 5, 24));
        EXPECT_EQ(masked, json({0, 229, 255, 255})) << "a pixel over the tolerance is drawn in the mask colour";

        // A passing test's tile opens its card, whose viewer then draws.
        b.eval("window.scrollTo(0,0)");
        click(".tile");
        ASSERT_TRUE(b.wait_for("(function(){var t=document.querySelector('.tile');var c=document.getElementById(t.dataset.card);"
                               "return !c.hidden && c.querySelector('.viewer').getAttribute('data-ready')==='1';})()"));
        b.eval("window.scrollTo(0,0)");
        save(b.screenshot(false), "report_ci_first_screen.png");
        for (const std::string& e : b.errors()) ADD_FAILURE() << "page: " << e;
    }
    fs::remove_all(dir);
}

// A change that fails 45 tests the same way (issue 32; one mip constant did so to the ci suite): the
// first screen shows the group, its representative's image in the viewer and one short approve
// command; the 44 others are folded, each opens its card; the page stays a few screens.
TEST(ReportBrowser, CiReportWith45FailuresOfOneCauseShowsOneGroupInTheFirstScreen) {
    if (!Browser::available()) GTEST_SKIP() << Browser::kChromium << " is not installed (Debian package chromium)";
    const fs::path dir = testutil::temp_dir("browser_ci45");
    const testutil::CiRun run = testutil::make_ci_run(dir / "run", 26, 45);
    report::write_report(run.results, run.dir, run.dir);
    {
        Browser b(dir / "profile", 1440, 900);
        b.open("file://" + (run.dir / "index.html").string(), kReady, 60);
        expect_loaded(b);
        const int height = b.eval("document.documentElement.scrollHeight").get<int>();
        std::cout << "ci report (26 pass, 45 fail) at 1440x900: " << height << " px\n";
        EXPECT_LT(height, 6000);
        EXPECT_EQ(b.eval("document.querySelectorAll('section.group').length").get<int>(), 1);
        EXPECT_EQ(b.eval("document.querySelector('section.group').getAttribute('data-members')").get<std::string>(), "45");
        // One card open, its viewer drawn; the others folded.
        EXPECT_EQ(b.eval("Array.from(document.querySelectorAll('section.test.s-fail')).filter(function(c){"
                         "return c.getBoundingClientRect().height>0;}).length")
                      .get<int>(),
                  1);
        EXPECT_EQ(body(b, "data-viewers-ready"), "1");
        auto bottom = [&](const std::string& sel) {
            return b.eval("document.querySelector(" + json(sel).dump() + ").getBoundingClientRect().bottom").get<double>();
        };
        EXPECT_LE(bottom("section.group h2.ghead"), 900);
        EXPECT_LE(bottom("section.group .cmd.bless-group"), 900);
        EXPECT_LE(b.eval("document.querySelector('section.group canvas.cv-img').getBoundingClientRect().top").get<double>() + 100,
                  900);
        // The group's command is short and names the shared option, not 45 names.
        const std::string cmd =
            b.eval("document.querySelector('section.group .cmd.bless-group code').textContent").get<std::string>();
        EXPECT_EQ(cmd, "iblcheck bless --suite 'ci' --filter '*mip_mapping=*'");
        const std::string all = b.eval("document.querySelector('.cmd.bless-all code').textContent").get<std::string>();
        EXPECT_EQ(all, cmd);
        // Unfolded, a member's tile opens its card and its viewer draws.
        b.eval("document.querySelector('details.gmore').open=true");
        auto [tx, ty] = b.centre_of("details.gmore .tile");
        b.click(tx, ty);
        ASSERT_TRUE(
            b.wait_for("(function(){var t=document.querySelector('details.gmore .tile');var c=document.getElementById("
                       "t.dataset.card);return !c.hidden && c.querySelector('.viewer').getAttribute('data-ready')==='1';})()"));
        b.eval("document.querySelector('details.gmore').open=false;window.scrollTo(0,0)");
        save(b.screenshot(false), "report_ci45_first_screen.png");
        for (const std::string& e : b.errors()) ADD_FAILURE() << "page: " << e;
    }
    fs::remove_all(dir);
}

// A measured run (the nightly: no baselines, nothing failed; issue 32) shows its tests as a table in
// the first screen, sorted by a click on accuracy, cost or drift since the last run in the history.
TEST(ReportBrowser, MeasuredRunIsATableSortableByAccuracyCostAndDrift) {
    if (!Browser::available()) GTEST_SKIP() << Browser::kChromium << " is not installed (Debian package chromium)";
    const fs::path dir = testutil::temp_dir("browser_measured");
    testutil::CiRun run = testutil::make_ci_run(dir / "run", 6, 0);
    json last = {{"commit", "0123456789ab"}, {"date", "2026-11-22T03:00:00Z"}, {"suite", "ci"}, {"tests", json::object()}};
    for (json& t : run.results["tests"]) {
        t.erase("comparisons");
        // Drift since the last run: test k was 0.2 + 0.001 k then; make test 2 jump by +50 %.
        const double now = t["accuracy"]["flip_mean"].get<double>();
        last["tests"][t["name"].get<std::string>()] = {
            {"verdict", "pass"}, {"flip_mean", t["name"] == run.results["tests"][2]["name"] ? now / 1.5 : now}};
    }
    report::write_report(run.results, run.dir, run.dir, {last});
    {
        Browser b(dir / "profile", 1440, 900);
        b.open("file://" + (run.dir / "index.html").string(), kReady);
        expect_loaded(b);
        const std::string table = "#tab-tests table.sortable";
        EXPECT_LE(b.eval("document.querySelector('" + table + "').getBoundingClientRect().top").get<double>(), 600);
        auto names = [&]() {
            return b.eval("Array.from(document.querySelectorAll('" + table +
                          " tbody tr')).map(function(r){return "
                          "r.getAttribute('data-name');})");
        };
        auto sort_by = [&](int column) {
            auto [x, y] = b.centre_of(fmt::format("{} th:nth-child({})", table, column));
            b.click(x, y);
        };
        const json& tests = run.results["tests"];
        sort_by(5); // drift %, ascending: test 2's +50 % last
        EXPECT_EQ(names()[5], tests[2]["name"]);
        sort_by(5); // again: descending, test 2 first
        EXPECT_EQ(names()[0], tests[2]["name"]);
        sort_by(4); // FLIP vs the truth ascending: 0.2 + 0.001 k in test order
        for (int k = 0; k < 6; ++k) EXPECT_EQ(names()[k], tests[k]["name"]) << k;
        sort_by(6); // SPIR-V instr/px: 6276 + k, ascending
        EXPECT_EQ(names()[0], tests[0]["name"]);
        EXPECT_EQ(b.eval("document.querySelector('" + table + " tbody tr td:nth-child(5)').textContent").get<std::string>(),
                  "+0.0");
        for (const std::string& e : b.errors()) ADD_FAILURE() << "page: " << e;
    }
    fs::remove_all(dir);
}

// Under a bright sun one exposure blows out half the spheres (issue 32): the viewer's false colour
// paints each pixel by its stop of luminance (the same band the C++ computes from the float data),
// and the exposure per sphere leaves no sphere blown out. Display only: the figures stay.
TEST(ReportBrowser, FalseColourAndExposurePerSphereShowWhatOneExposureBlowsOut) {
    if (!Browser::available()) GTEST_SKIP() << Browser::kChromium << " is not installed (Debian package chromium)";
    const fs::path dir = testutil::temp_dir("browser_false");
    const testutil::CiRun run = testutil::make_ci_run(dir / "run", 3, 1);
    report::write_report(run.results, run.dir, run.dir);
    {
        Browser b(dir / "profile", 1440, 900);
        b.open("file://" + (run.dir / "index.html").string(), kReady);
        expect_loaded(b);
        const std::string card = "section.test.s-fail";
        auto mode = [&](const std::string& m) {
            b.eval("(function(){var s=document.querySelector('" + card + " select.dmode');s.value='" + m +
                   "';s.dispatchEvent(new Event('change'));})()");
        };
        auto [x0, y0] = b.centre_of(card + " button.ev-0");
        b.click(x0, y0);
        mode("false");
        EXPECT_FALSE(b.eval("document.querySelector('" + card + " .fclegend').hidden").get<bool>());
        const json palette = b.eval("window.iblcheckFalseColour");
        ASSERT_EQ(palette.size(), 15u);
        int checked = 0;
        for (int sphere = 0; sphere < run.width / 48; sphere += 2) {
            const int px = 24 + 48 * sphere, py = 24;
            const cv::Vec3f c = run.failing_test.at<cv::Vec3f>(py, px);
            const double L = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            if (!(L > 0)) continue;
            const int band = int(std::floor(std::log2(L / 0.18) + 0.5)) + 7;
            const json want = band < 0 ? json({0, 0, 0}) : band > 14 ? json({255, 255, 255}) : palette[band];
            const json got = b.eval(fmt::format("Array.from(document.querySelector('{} canvas.cv-img').getContext('2d')"
                                                ".getImageData({},{},1,1).data).slice(0,3)",
                                                card, px, py));
            EXPECT_EQ(got, want) << "sphere " << sphere << " L " << L;
            ++checked;
        }
        EXPECT_GE(checked, 5);
        save(b.screenshot(false), "report_false_colour.png");
        // Blown-out pixels (every channel at 254 or more): some at +6 EV with one exposure, none per sphere.
        const std::string blown = "(function(){var c=document.querySelector('" + card +
                                  " canvas.cv-img'),d=c.getContext('2d').getImageData(0,0,c.width,c.height).data,n=0;"
                                  "for(var i=0;i<d.length;i+=4)if(d[i]>=254&&d[i+1]>=254&&d[i+2]>=254)n++;return n;})()";
        mode("exp");
        b.eval("(function(){var e=document.querySelector('" + card +
               " input.ev');e.value=6;e.dispatchEvent(new Event('input'));})()");
        EXPECT_GT(b.eval(blown).get<int>(), 100);
        mode("sphere");
        auto [ax, ay] = b.centre_of(card + " button.ev-auto");
        b.click(ax, ay);
        EXPECT_EQ(b.eval(blown).get<int>(), 0);
        save(b.screenshot(false), "report_exposure_per_sphere.png");
        for (const std::string& e : b.errors()) ADD_FAILURE() << "page: " << e;
    }
    fs::remove_all(dir);
}
} // namespace test_report_browser
