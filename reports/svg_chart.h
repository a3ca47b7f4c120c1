// SVG charts written by the report (no library): scatter/line charts with axes, ticks, legend,
// <title> tooltips and the Pareto front, and history sparklines. Every chart is
// <svg class="chart" data-chart="ID" data-points="N"> and every plotted point <circle class="point">,
// so tests (and the page's own load check) can count them.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "reports/drift.h"

namespace iblcheck::report {

// Escapes & < > " ' for text and attribute values.
std::string html_escape(std::string_view s);
// Short human number: 0.0123, 41.2, 1.2e-05.
std::string fmt_num(double v);

struct ChartPoint {
    double x = 0, y = 0;
    std::optional<double> xlo, xhi; // a horizontal range drawn through the point (repeated timings)
    std::string label;              // drawn next to the point (may be empty)
    std::string tooltip;            // <title>
    std::string href;               // optional link (e.g. "#t-3": the test's card)
    bool failed = false;            // the test failed in this run: a red ring marks it (issue 32)
};

struct ChartSeries {
    std::string name; // legend
    std::string color;
    bool dashed = false;
    bool connect = false; // draw a line through the points (sorted by x)
    // circle, square, triangle, diamond, triangle-down, cross, plus, star, hexagon, pentagon,
    // triangle-left, triangle-right, hourglass, bowtie (marker_shapes())
    std::string marker = "circle";
    bool hollow = false; // marker drawn as an outline
    std::vector<ChartPoint> points;
};

inline ChartSeries make_series(std::string name, std::string color, bool dashed = false, bool connect = false) {
    ChartSeries s;
    s.name = std::move(name);
    s.color = std::move(color);
    s.dashed = dashed;
    s.connect = connect;
    return s;
}

struct ChartAxis {
    std::string label;
    bool log = false;
    std::optional<double> min, max; // fixed domain; otherwise from the data
};

struct Chart {
    std::string id; // data-chart
    std::string title;
    std::string note; // a line under the title
    ChartAxis x, y;
    std::vector<ChartSeries> series;
    bool pareto = false;                   // draw the Pareto front over all points (lower-left is better)
    double width = 640, plot_height = 262; // a small multiple is smaller
    bool legend = true;                    // small multiples share one legend outside the panels
};

// The marker shapes a series may use, in the order variants are given them.
const std::vector<std::string>& marker_shapes();
// An SVG element (class "point" plus `cls`) drawing `shape` centred on (x, y).
std::string marker_svg(const std::string& shape, double x, double y, double r, const std::string& fill, const std::string& cls,
                       bool hollow);

std::string render_chart(const Chart& chart);

// Indices of the points on the Pareto front (minimise both x and y): a point is on the front
// unless another point is at least as good in both and better in one.
std::vector<size_t> pareto_front(const std::vector<std::pair<double, double>>& pts);

struct SparkRun {
    std::string commit, date;
    std::optional<double> value;
    std::optional<double> lo, hi; // the run's measured range (repeated timings), drawn as a bar
};

struct Sparkline {
    std::string svg;
    std::string moved; // the flag's text ("+3.1 % at c4 (noise floor 0.0017)"); else ""
    std::string moved_commit;
    std::string range; // "0.03–0.052 ms": the values' span
    size_t points = 0;
};

// A trend line over `runs` (oldest first); `flag` (drift.h) marks the run that moved.
Sparkline render_sparkline(const std::string& id, const std::string& test_name, const std::vector<SparkRun>& runs,
                           const std::string& unit, const std::optional<Flag>& flag);

} // namespace iblcheck::report
