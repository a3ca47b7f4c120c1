// SVG charts written by the report (no library): scatter/line charts with axes, ticks, legend,
// <title> tooltips and the Pareto front, and history sparklines. Every chart is
// <svg class="chart" data-chart="ID" data-points="N"> and every plotted point <circle class="point">,
// so tests (and the page's own load check) can count them.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace iblcheck::report {

// Escapes & < > " ' for text and attribute values.
std::string html_escape(std::string_view s);
// Short human number: 0.0123, 41.2, 1.2e-05.
std::string fmt_num(double v);

struct ChartPoint {
    double x = 0, y = 0;
    std::string label;   // drawn next to the point (may be empty)
    std::string tooltip; // <title>
    std::string href;    // optional link (e.g. "#t-3": the test's card)
};

struct ChartSeries {
    std::string name;  // legend
    std::string color;
    bool dashed = false;
    bool connect = false; // draw a line through the points (sorted by x)
    std::vector<ChartPoint> points;
};

struct ChartAxis {
    std::string label;
    bool log = false;
    std::optional<double> min, max; // fixed domain; otherwise from the data
};

struct Chart {
    std::string id;    // data-chart
    std::string title;
    std::string note;  // a line under the title
    ChartAxis x, y;
    std::vector<ChartSeries> series;
    bool pareto = false; // draw the Pareto front over all points (lower-left is better)
};

std::string render_chart(const Chart& chart);

// Indices of the points on the Pareto front (minimise both x and y): a point is on the front
// unless another point is at least as good in both and better in one.
std::vector<size_t> pareto_front(const std::vector<std::pair<double, double>>& pts);

struct SparkRun {
    std::string commit, date;
    std::optional<double> value;
};

struct Sparkline {
    std::string svg;
    std::string moved;      // "+35% at f554dd9" when the largest jump passes the threshold; else ""
    std::string moved_commit;
    std::string range;      // "0.03–0.052 ms": the values' span
    size_t points = 0;
};

// A trend line over `runs` (oldest first). The largest relative jump between consecutive values
// is marked with the commit that made it when it exceeds `rel_threshold` (0.10 = 10 %) and
// `abs_floor` (ignores noise on values near 0).
Sparkline render_sparkline(const std::string& id, const std::string& test_name, const std::vector<SparkRun>& runs,
                           double rel_threshold, double abs_floor, const std::string& unit);

} // namespace iblcheck::report
