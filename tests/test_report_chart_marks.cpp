// The charts read on a nightly (issue 32): a glyph per variant family (26 families shared 18 glyphs),
// x tick labels that do not run together ("100000200000"), and the run's failures marked.
#include <gtest/gtest.h>

#include <regex>
#include <set>

#include "reports/svg_chart.h"

using namespace iblcheck::report;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report_chart_marks {

TEST(ReportChartMarks, TwentySixFamiliesHaveTwentySixGlyphs) {
    const auto& shapes = marker_shapes();
    std::set<std::string> distinct(shapes.begin(), shapes.end());
    EXPECT_EQ(distinct.size(), shapes.size());
    EXPECT_GE(2 * shapes.size(), 26u) << "solid and hollow: one glyph per family of the nightly";
    std::set<std::string> drawn; // each shape draws differently
    for (const std::string& s : shapes) EXPECT_TRUE(drawn.insert(marker_svg(s, 10, 10, 4, "#000", "", false)).second) << s;
}

TEST(ReportChartMarks, XTickLabelsAreShortAndDoNotTouchAndFailuresAreRinged) {
    Chart c;
    c.id = "t";
    c.width = 300; // a small multiple
    c.x = {"cost", false, {}, {}};
    c.y = {"error", false, {}, {}};
    ChartSeries s = make_series("mobile", "#1c7ed6");
    for (int k = 0; k <= 6; ++k) {
        ChartPoint p;
        p.x = 50000.0 * k;
        p.y = 0.1 + 0.01 * k;
        p.failed = k == 3;
        s.points.push_back(p);
    }
    c.series.push_back(s);
    const std::string svg = render_chart(c);
    std::regex tl(R"re(<text class="tl" x="([0-9.]+)" y="[0-9.]+" text-anchor="middle">([^<]*)</text>)re");
    double last_right = -1e9;
    int labels = 0;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), tl); it != std::sregex_iterator(); ++it) {
        const double x = std::stod((*it)[1]);
        const std::string label = (*it)[2];
        EXPECT_LE(label.size(), 4u) << label; // "300k", not "300000"
        EXPECT_GT(x - 3.3 * double(label.size()), last_right) << label << " touches the label before it";
        last_right = x + 3.3 * double(label.size());
        ++labels;
    }
    EXPECT_GE(labels, 3);
    EXPECT_NE(svg.find(">150k<"), std::string::npos) << svg.substr(0, 2000);
    size_t rings = 0;
    for (size_t p = svg.find("<circle class=\"failed\""); p != std::string::npos; p = svg.find("<circle class=\"failed\"", p + 1))
        ++rings;
    EXPECT_EQ(rings, 1u);
}
} // namespace test_report_chart_marks
