#include "reports/svg_chart.h"
#include "kernel/markup.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <fmt/format.h>

namespace iblcheck::report {

std::string html_escape(std::string_view s) { return escape_markup(s); }

std::string fmt_num(double v) {
    if (!std::isfinite(v)) return std::isnan(v) ? "NaN" : (v > 0 ? "inf" : "-inf");
    if (v == 0) return "0";
    const double a = std::fabs(v);
    if (a >= 1e6 || a < 1e-4) return fmt::format("{:.3g}", v);
    if (a >= 100) return v == std::round(v) ? fmt::format("{:.0f}", v) : fmt::format("{:.1f}", v);
    return fmt::format("{:.4g}", v);
}

std::vector<size_t> pareto_front(const std::vector<std::pair<double, double>>& p) {
    std::vector<size_t> front;
    for (size_t i = 0; i < p.size(); ++i) {
        bool dominated = false;
        for (size_t j = 0; j < p.size() && !dominated; ++j) {
            if (j == i) continue;
            dominated =
                p[j].first <= p[i].first && p[j].second <= p[i].second && (p[j].first < p[i].first || p[j].second < p[i].second);
        }
        if (!dominated) front.push_back(i);
    }
    return front;
}

const std::vector<std::string>& marker_shapes() {
    // 14 shapes, solid then hollow: 28 glyphs, one per variant family (the nightly has 26; issue 32).
    static const std::vector<std::string> shapes{"circle",        "square",         "triangle",  "diamond", "triangle-down",
                                                 "cross",         "plus",           "star",      "hexagon", "pentagon",
                                                 "triangle-left", "triangle-right", "hourglass", "bowtie"};
    return shapes;
}

std::string marker_svg(const std::string& shape, double x, double y, double r, const std::string& fill, const std::string& cls,
                       bool hollow) {
    const std::string c = "point" + std::string(hollow ? " hollow" : "") + (cls.empty() ? "" : " " + cls);
    // A hollow marker is an outline in the colour (inline style: it must win over the charts' CSS).
    const std::string paint = hollow ? fmt::format("fill=\"#fff\" stroke=\"{0}\" style=\"stroke:{0}\"", html_escape(fill))
                                     : fmt::format("fill=\"{}\" stroke=\"#fff\"", html_escape(fill));
    auto poly = [&](std::vector<std::pair<double, double>> pts) {
        std::string d;
        for (size_t i = 0; i < pts.size(); ++i)
            d += fmt::format("{}{:.1f},{:.1f}", i ? "L" : "M", x + pts[i].first * r, y + pts[i].second * r);
        return fmt::format("<path class=\"{}\" d=\"{}Z\" {}", c, d, paint);
    };
    if (shape == "square") return poly({{-0.85, -0.85}, {0.85, -0.85}, {0.85, 0.85}, {-0.85, 0.85}});
    if (shape == "triangle") return poly({{0, -1.15}, {1.05, 0.75}, {-1.05, 0.75}});
    if (shape == "triangle-down") return poly({{0, 1.15}, {1.05, -0.75}, {-1.05, -0.75}});
    if (shape == "diamond") return poly({{0, -1.2}, {1.0, 0}, {0, 1.2}, {-1.0, 0}});
    if (shape == "triangle-left") return poly({{-1.15, 0}, {0.75, -1.05}, {0.75, 1.05}});
    if (shape == "triangle-right") return poly({{1.15, 0}, {-0.75, -1.05}, {-0.75, 1.05}});
    if (shape == "hourglass") return poly({{-1, -1}, {1, -1}, {0, 0}, {1, 1}, {-1, 1}, {0, 0}});
    if (shape == "bowtie") return poly({{-1, -1}, {0, 0}, {1, -1}, {1, 1}, {0, 0}, {-1, 1}});
    if (shape == "pentagon") return poly({{0.0, -1.1}, {1.05, -0.34}, {0.65, 0.89}, {-0.65, 0.89}, {-1.05, -0.34}});
    if (shape == "cross")
        return poly({{-1, -0.6},
                     {-0.6, -1},
                     {0, -0.4},
                     {0.6, -1},
                     {1, -0.6},
                     {0.4, 0},
                     {1, 0.6},
                     {0.6, 1},
                     {0, 0.4},
                     {-0.6, 1},
                     {-1, 0.6},
                     {-0.4, 0}});
    if (shape == "plus")
        return poly({{-0.3, -1},
                     {0.3, -1},
                     {0.3, -0.3},
                     {1, -0.3},
                     {1, 0.3},
                     {0.3, 0.3},
                     {0.3, 1},
                     {-0.3, 1},
                     {-0.3, 0.3},
                     {-1, 0.3},
                     {-1, -0.3},
                     {-0.3, -0.3}});
    if (shape == "star") {
        std::vector<std::pair<double, double>> p;
        for (int i = 0; i < 10; ++i) {
            const double a = -1.5707963 + i * 0.6283185, rr = i % 2 ? 0.5 : 1.25;
            p.emplace_back(rr * std::cos(a), rr * std::sin(a));
        }
        return poly(p);
    }
    if (shape == "hexagon") {
        std::vector<std::pair<double, double>> p;
        for (int i = 0; i < 6; ++i) p.emplace_back(1.05 * std::cos(i * 1.0471976), 1.05 * std::sin(i * 1.0471976));
        return poly(p);
    }
    return fmt::format("<circle class=\"{}\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{}\" {}", c, x, y, r, paint);
}

namespace {

struct Scale {
    double lo = 0, hi = 1, p0 = 0, p1 = 1; // data domain -> pixel range
    bool log = false;
    std::vector<double> ticks;
    double operator()(double v) const {
        double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
        return p0 + t * (p1 - p0);
    }
};

double nice_step(double raw) {
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / p;
    return (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * p;
}

Scale make_scale(const ChartAxis& ax, std::vector<double> vals, double p0, double p1) {
    Scale s;
    s.p0 = p0;
    s.p1 = p1;
    s.log = ax.log;
    double mn = vals.empty() ? (ax.log ? 1 : 0) : *std::min_element(vals.begin(), vals.end());
    double mx = vals.empty() ? (ax.log ? 10 : 1) : *std::max_element(vals.begin(), vals.end());
    if (ax.min) mn = *ax.min;
    if (ax.max) mx = *ax.max;
    if (ax.log) {
        // The domain snaps to the nearest 1-2-5 steps around the data, not to whole decades.
        auto step_down = [](double v) {
            const double p = std::pow(10.0, std::floor(std::log10(v)));
            return v >= 5 * p ? 5 * p : v >= 2 * p ? 2 * p : p;
        };
        auto step_up = [](double v) {
            const double p = std::pow(10.0, std::floor(std::log10(v)));
            return v <= p * 1.0000001 ? p : v <= 2 * p ? 2 * p : v <= 5 * p ? 5 * p : 10 * p;
        };
        s.lo = ax.min ? *ax.min : step_down(mn);
        s.hi = ax.max ? *ax.max : step_up(mx);
        if (s.hi <= s.lo) s.hi = step_up(s.lo * 1.01);
        const int e0 = int(std::floor(std::log10(s.lo))), e1 = int(std::ceil(std::log10(s.hi)));
        const bool fine = std::log10(s.hi / s.lo) <= 3.01;
        for (int e = e0; e <= e1; ++e)
            for (double m : {1.0, 2.0, 5.0}) {
                if (m != 1.0 && !fine) continue;
                const double v = m * std::pow(10.0, e);
                if (v >= s.lo * 0.999 && v <= s.hi * 1.001) s.ticks.push_back(v);
            }
        return s;
    }
    if (!ax.min && mn >= 0) mn = 0; // errors and costs: start at 0
    if (mx <= mn) mx = mn + (std::fabs(mn) > 0 ? std::fabs(mn) * 0.5 : 1.0);
    if (!ax.max && !vals.empty()) mx += 0.06 * (mx - mn); // keep the top point off the frame
    const double step = nice_step((mx - mn) / 5);
    s.lo = ax.min ? mn : std::floor(mn / step) * step;
    s.hi = ax.max ? mx : std::ceil(mx / step - 1e-9) * step;
    if (s.hi <= s.lo) s.hi = s.lo + step;
    for (double v = std::ceil(s.lo / step - 1e-9) * step; v <= s.hi + step * 1e-6; v += step)
        s.ticks.push_back(std::fabs(v) < step * 1e-9 ? 0 : v);
    return s;
}

struct Box {
    double x0, y0, x1, y1;
    bool hits(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

// A point the chart draws, with its series.
struct PlotPoint {
    const ChartPoint* p;
    size_t series;
};

// The chart's points: those a log axis cannot show (<= 0) or that are not finite are left out and
// counted in `skipped`; `xs`, `ys` collect the values the axes must span (ranges included).
std::vector<PlotPoint> plotted_points(const Chart& c, std::vector<double>& xs, std::vector<double>& ys, size_t& skipped) {
    std::vector<PlotPoint> pts;
    for (size_t si = 0; si < c.series.size(); ++si)
        for (const ChartPoint& p : c.series[si].points) {
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || (c.x.log && p.x <= 0) || (c.y.log && p.y <= 0)) {
                ++skipped;
                continue;
            }
            pts.push_back({&p, si});
            xs.push_back(p.x);
            ys.push_back(p.y);
            if (p.xlo && std::isfinite(*p.xlo) && (!c.x.log || *p.xlo > 0)) xs.push_back(*p.xlo);
            if (p.xhi && std::isfinite(*p.xhi)) xs.push_back(*p.xhi);
        }
    return pts;
}

// The plot's frame in SVG units and its two scales.
struct Plot {
    double px0, px1, py0, py1;
    Scale sx, sy;
};

struct LegendItem {
    std::string name, color;
    bool dashed, pareto;
    double x, y;
};

// The legend below the plot, in rows that wrap (so two charts fit side by side); `height` receives
// the chart's height.
std::vector<LegendItem> layout_legend(const Chart& c, double W, double px0, double py1, double& height) {
    std::vector<LegendItem> legend;
    if (c.legend) {
        for (const ChartSeries& s : c.series)
            if (!s.name.empty()) legend.push_back({s.name, s.color, s.dashed, false, 0, 0});
        if (c.pareto) legend.push_back({"Pareto front (lower-left is better)", "#212529", true, true, 0, 0});
    }
    double lx = px0 - 40, ly = py1 + (legend.empty() ? 46 : 64);
    for (LegendItem& it : legend) {
        const double w = 34 + 6.1 * double(it.name.size()) + 14;
        if (lx + w > W - 4 && lx > px0 - 40) lx = px0 - 40, ly += 18;
        it.x = lx;
        it.y = ly;
        lx += w;
    }
    height = legend.empty() ? py1 + 46 : ly + 14;
    return legend;
}

// A tick's label, short: "250k" and "1.5M" rather than "250000" (issue 32: "100000200000").
std::string tick_label(double t) {
    const double a = std::fabs(t);
    if (a >= 1e6) return fmt_num(t / 1e6) + "M";
    if (a >= 1e4) return fmt_num(t / 1e3) + "k";
    return fmt_num(t);
}

// Frame, grid, ticks, axis labels ("no data" when nothing is plotted); an x tick whose label would
// touch the one before keeps its grid line and loses its label.
void axes_svg(std::string& o, const Chart& c, const Plot& pl, bool empty) {
    auto out = std::back_inserter(o);
    const double px0 = pl.px0, px1 = pl.px1, py0 = pl.py0, py1 = pl.py1;
    fmt::format_to(out, "<rect class=\"plot\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", px0, py0, px1 - px0, py1 - py0);
    double last_right = -1e9;
    for (double t : pl.sx.ticks) {
        const double x = pl.sx(t);
        const std::string label = tick_label(t);
        const double half = 3.3 * double(label.size()); // ~6.6 px a character at the ticks' 11 px
        const bool room = x - half >= last_right + 4;
        if (room) last_right = x + half;
        fmt::format_to(
            out,
            "<line class=\"grid\" x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\"/>"
            "<line class=\"tick\" x1=\"{0:.1f}\" y1=\"{2}\" x2=\"{0:.1f}\" y2=\"{3}\"/>{5}\n",
            x, py0, py1, py1 + 5, py1 + 18,
            room ? fmt::format("<text class=\"tl\" x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{}</text>", x, py1 + 18, label)
                 : std::string());
    }
    for (double t : pl.sy.ticks) {
        const double y = pl.sy(t);
        fmt::format_to(out,
                       "<line class=\"grid\" x1=\"{1}\" y1=\"{0:.1f}\" x2=\"{2}\" y2=\"{0:.1f}\"/>"
                       "<line class=\"tick\" x1=\"{3}\" y1=\"{0:.1f}\" x2=\"{1}\" y2=\"{0:.1f}\"/>"
                       "<text class=\"tl\" x=\"{4}\" y=\"{5:.1f}\" text-anchor=\"end\">{6}</text>\n",
                       y, px0, px1, px0 - 5, px0 - 8, y + 4, tick_label(t));
    }
    fmt::format_to(out, "<text class=\"al\" x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}{}</text>\n", (px0 + px1) / 2, py1 + 36,
                   html_escape(c.x.label), c.x.log ? " (log scale)" : "");
    fmt::format_to(out, "<text class=\"al\" transform=\"translate(16 {}) rotate(-90)\" text-anchor=\"middle\">{}{}</text>\n",
                   (py0 + py1) / 2, html_escape(c.y.label), c.y.log ? " (log scale)" : "");
    if (empty)
        fmt::format_to(out, "<text class=\"cnote\" x=\"{}\" y=\"{}\" text-anchor=\"middle\">no data</text>\n", (px0 + px1) / 2,
                       (py0 + py1) / 2);
}

// Pareto front: staircase through the non-dominated points (everything above/right is worse).
void pareto_svg(std::string& o, const std::vector<PlotPoint>& pts, const Plot& pl) {
    std::vector<std::pair<double, double>> xy;
    for (auto& p : pts) xy.emplace_back(p.p->x, p.p->y);
    std::vector<size_t> f = pareto_front(xy);
    std::sort(f.begin(), f.end(), [&](size_t a, size_t b) { return xy[a] < xy[b]; });
    std::string poly;
    for (size_t k = 0; k < f.size(); ++k) {
        const double x = pl.sx(xy[f[k]].first), y = pl.sy(xy[f[k]].second);
        if (k > 0) poly += fmt::format("{:.1f},{:.1f} ", x, pl.sy(xy[f[k - 1]].second));
        poly += fmt::format("{:.1f},{:.1f} ", x, y);
    }
    if (f.empty()) return;
    poly += fmt::format("{:.1f},{:.1f}", pl.px1, pl.sy(xy[f.back()].second));
    std::string members;
    for (size_t k : f) members += (members.empty() ? "" : "; ") + pts[k].p->label;
    fmt::format_to(std::back_inserter(o),
                   "<polyline class=\"pareto-front\" data-front=\"{}\" points=\"{}\"><title>Pareto front: {}"
                   "</title></polyline>\n",
                   f.size(), poly, html_escape(members));
    for (size_t k : f)
        fmt::format_to(std::back_inserter(o), "<circle class=\"front-ring\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"7\"/>\n",
                       pl.sx(xy[k].first), pl.sy(xy[k].second));
}

// The lines of the series that connect their points, in x order.
void series_lines_svg(std::string& o, const Chart& c, const std::vector<PlotPoint>& pts, const Plot& pl) {
    for (size_t si = 0; si < c.series.size(); ++si) {
        const ChartSeries& s = c.series[si];
        if (!s.connect) continue;
        std::vector<std::pair<double, double>> xy;
        for (auto& p : pts)
            if (p.series == si) xy.emplace_back(p.p->x, p.p->y);
        std::sort(xy.begin(), xy.end());
        if (xy.size() < 2) continue;
        std::string poly;
        for (auto& [x, y] : xy) poly += fmt::format("{:.1f},{:.1f} ", pl.sx(x), pl.sy(y));
        fmt::format_to(std::back_inserter(o),
                       "<polyline class=\"series{}\" data-series=\"{}\" stroke=\"{}\" points=\"{}\"><title>{}</title>"
                       "</polyline>\n",
                       s.dashed ? " dashed" : "", html_escape(s.name), html_escape(s.color), poly, html_escape(s.name));
    }
}

// Points with their ranges, tooltips and links, and labels (placed greedily where they overlap no
// point and no earlier label; the tooltip always has it).
void points_svg(std::string& o, const Chart& c, const std::vector<PlotPoint>& pts, const Plot& pl) {
    auto out = std::back_inserter(o);
    std::vector<Box> placed;
    for (auto& p : pts) {
        const double x = pl.sx(p.p->x), y = pl.sy(p.p->y);
        placed.push_back({x - 5, y - 5, x + 5, y + 5}); // labels keep off every point
    }
    for (auto& p : pts) {
        const ChartSeries& s = c.series[p.series];
        const double x = pl.sx(p.p->x), y = pl.sy(p.p->y);
        if (p.p->xlo && p.p->xhi && (!c.x.log || *p.p->xlo > 0))
            fmt::format_to(out, "<line class=\"range\" x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\"/>",
                           pl.sx(*p.p->xlo), y, pl.sx(*p.p->xhi), y, html_escape(s.color));
        if (p.p->failed)
            fmt::format_to(out,
                           "<circle class=\"failed\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"8.5\" fill=\"none\" "
                           "stroke=\"#e03131\" stroke-width=\"2\"><title>failed in this run</title></circle>",
                           x, y);
        std::string circle = marker_svg(s.marker, x, y, 4.5, s.color, "", s.hollow) +
                             fmt::format(" data-series=\"{}\" data-x=\"{}\" data-y=\"{}\" data-label=\"{}\"><title>{}</title>{}",
                                         html_escape(s.name), p.p->x, p.p->y, html_escape(p.p->label),
                                         html_escape(p.p->tooltip.empty() ? p.p->label : p.p->tooltip),
                                         s.marker == "circle" ? "</circle>" : "</path>");
        if (!p.p->href.empty()) circle = fmt::format("<a href=\"{}\">{}</a>", html_escape(p.p->href), circle);
        o += circle;
        if (!p.p->label.empty()) {
            const double w = 5.6 * double(p.p->label.size()), h = 11;
            for (double dy : {-6.0, 6.0, -17.0, 17.0, -28.0, 28.0}) {
                double lx = x + 7, ly = y + dy;
                if (lx + w > pl.px1 + 15) lx = x - 7 - w; // keep labels inside the plot
                Box b{lx, ly - h + 2, lx + w, ly + 2};
                if (b.y0 < pl.py0 || b.y1 > pl.py1 || b.x0 < pl.px0 - 2) continue;
                if (std::any_of(placed.begin(), placed.end(), [&](const Box& q) { return q.hits(b); })) continue;
                placed.push_back(b);
                fmt::format_to(out, "<text class=\"pl\" x=\"{:.1f}\" y=\"{:.1f}\">{}</text>", lx, ly, html_escape(p.p->label));
                break;
            }
        }
        o += '\n';
    }
}

void legend_svg(std::string& o, const std::vector<LegendItem>& legend) {
    for (const LegendItem& it : legend) {
        if (it.pareto)
            fmt::format_to(std::back_inserter(o),
                           "<g class=\"legend\"><line class=\"pareto-front\" x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" "
                           "y2=\"{1:.1f}\"/><text x=\"{3:.1f}\" y=\"{4:.1f}\">{5}</text></g>\n",
                           it.x, it.y, it.x + 26, it.x + 32, it.y + 4, html_escape(it.name));
        else
            fmt::format_to(std::back_inserter(o),
                           "<g class=\"legend\"><line class=\"series{0}\" x1=\"{1:.1f}\" y1=\"{2:.1f}\" x2=\"{3:.1f}\" "
                           "y2=\"{2:.1f}\" stroke=\"{4}\"/><circle cx=\"{5:.1f}\" cy=\"{2:.1f}\" r=\"4\" fill=\"{4}\"/>"
                           "<text x=\"{6:.1f}\" y=\"{7:.1f}\">{8}</text></g>\n",
                           it.dashed ? " dashed" : "", it.x, it.y, it.x + 26, html_escape(it.color), it.x + 13, it.x + 32,
                           it.y + 4, html_escape(it.name));
    }
}

} // namespace

std::string render_chart(const Chart& c) {
    std::vector<double> xs, ys;
    size_t skipped = 0;
    const std::vector<PlotPoint> pts = plotted_points(c, xs, ys, skipped);
    // Layout: plot on top, legend below it.
    const double W = c.width, px0 = 64, px1 = W - 18, py0 = c.note.empty() ? 30 : 44, py1 = py0 + c.plot_height;
    double H = 0;
    const std::vector<LegendItem> legend = layout_legend(c, W, px0, py1, H);
    const Plot pl{px0, px1, py0, py1, make_scale(c.x, xs, px0, px1), make_scale(c.y, ys, py1, py0)};

    std::string o;
    auto out = std::back_inserter(o);
    fmt::format_to(out,
                   "<svg class=\"chart\" data-chart=\"{}\" data-points=\"{}\" data-series=\"{}\" data-skipped=\"{}\" "
                   "xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" role=\"img\">\n",
                   html_escape(c.id), pts.size(), c.series.size(), skipped, W, H, W, H);
    fmt::format_to(out, "<title>{}</title>\n", html_escape(c.title));
    fmt::format_to(out, "<text class=\"ctitle\" x=\"{}\" y=\"18\">{}</text>\n", px0 - 40, html_escape(c.title));
    if (!c.note.empty())
        fmt::format_to(out, "<text class=\"cnote\" x=\"{}\" y=\"33\">{}</text>\n", px0 - 40, html_escape(c.note));
    axes_svg(o, c, pl, pts.empty());
    if (c.pareto && !pts.empty()) pareto_svg(o, pts, pl);
    series_lines_svg(o, c, pts, pl);
    points_svg(o, c, pts, pl);
    legend_svg(o, legend);
    o += "</svg>\n";
    return o;
}

Sparkline render_sparkline(const std::string& id, const std::string& test_name, const std::vector<SparkRun>& runs,
                           const std::string& unit, const std::optional<Flag>& flag) {
    Sparkline r;
    const double W = 200, H = 44, x0 = 4, x1 = W - 4, y0 = 13, y1 = H - 4;
    std::vector<size_t> idx;
    for (size_t i = 0; i < runs.size(); ++i)
        if (runs[i].value && std::isfinite(*runs[i].value)) idx.push_back(i);
    r.points = idx.size();
    double mn = 0, mx = 1;
    if (!idx.empty()) {
        mn = mx = *runs[idx[0]].value;
        for (size_t i : idx) {
            mn = std::min(mn, *runs[i].value), mx = std::max(mx, *runs[i].value);
            if (runs[i].lo && std::isfinite(*runs[i].lo)) mn = std::min(mn, *runs[i].lo);
            if (runs[i].hi && std::isfinite(*runs[i].hi)) mx = std::max(mx, *runs[i].hi);
        }
    }
    if (!idx.empty()) r.range = fmt::format("{}\u2013{}{}", fmt_num(mn), fmt_num(mx), unit);
    // The vertical span is at least 20 % of the values, so run-to-run noise of a few percent reads
    // as flat instead of being stretched to the full height.
    const double min_span = std::max(0.2 * std::max(std::fabs(mn), std::fabs(mx)), 1e-9);
    if (mx - mn < min_span) {
        const double mid = 0.5 * (mn + mx);
        mn = mid - 0.5 * min_span;
        mx = mid + 0.5 * min_span;
    }
    const double n = double(std::max<size_t>(runs.size(), 2) - 1);
    auto X = [&](size_t i) { return x0 + (x1 - x0) * double(i) / n; };
    auto Y = [&](double v) { return y1 - (y1 - y0) * (v - mn) / (mx - mn); };

    std::string o;
    auto out = std::back_inserter(o);
    fmt::format_to(out,
                   "<svg class=\"chart spark\" data-chart=\"{}\" data-test=\"{}\" data-points=\"{}\" data-flagged=\"{}\" "
                   "xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\">",
                   html_escape(id), html_escape(test_name), idx.size(), flag ? 1 : 0, W, H, W, H);
    if (flag && flag->index < runs.size()) {
        const SparkRun& run = runs[flag->index];
        r.moved_commit = run.commit;
        r.moved = flag->text;
        const double x = X(flag->index);
        fmt::format_to(out,
                       "<line class=\"moved\" x1=\"{0:.1f}\" y1=\"9\" x2=\"{0:.1f}\" y2=\"{1}\"/>"
                       "<text class=\"moved\" x=\"{2:.1f}\" y=\"9\" text-anchor=\"{3}\" data-commit=\"{4}\">{4}</text>",
                       x, H, x, x > W / 2 ? "end" : "start", html_escape(run.commit));
    }
    for (size_t i : idx)
        if (runs[i].lo && runs[i].hi && *runs[i].hi > *runs[i].lo)
            fmt::format_to(out, "<line class=\"rg\" x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\"/>", X(i),
                           Y(*runs[i].lo), Y(*runs[i].hi));
    if (idx.size() >= 2) {
        std::string poly;
        for (size_t i : idx) poly += fmt::format("{:.1f},{:.1f} ", X(i), Y(*runs[i].value));
        fmt::format_to(out, "<polyline class=\"sl\" points=\"{}\"/>", poly);
    }
    for (size_t k = 0; k < idx.size(); ++k) {
        const SparkRun& run = runs[idx[k]];
        std::string range;
        if (run.lo && run.hi) range = fmt::format(" (range {}\u2013{})", fmt_num(*run.lo), fmt_num(*run.hi));
        fmt::format_to(out,
                       "<circle class=\"point{}\" cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{}\" data-commit=\"{}\" data-y=\"{}\">"
                       "<title>{} {}: {}{}{}</title></circle>",
                       k + 1 == idx.size() ? " last" : "", X(idx[k]), Y(*run.value), k + 1 == idx.size() ? 3 : 1.8,
                       html_escape(run.commit), *run.value, html_escape(run.commit), html_escape(run.date), fmt_num(*run.value),
                       html_escape(unit), html_escape(range));
    }
    o += "</svg>";
    r.svg = std::move(o);
    return r;
}

} // namespace iblcheck::report
