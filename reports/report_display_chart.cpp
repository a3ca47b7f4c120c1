// Linear against display scoring (issue 29): the charts tab's panel per scene and environment of the
// tests measured against the truth in both spaces (a suite with a "display": suite.h), x the mean
// HDR-FLIP in linear HDR, y the mean LDR-FLIP where a player sees it, and a measured statement of
// how the ranking changes: Spearman's rank correlation, how many tests move, the largest moves.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report::html {

namespace {

// 1-based ranks of `v` (smallest first), ties given their mean rank.
std::vector<double> ranks(const std::vector<double>& v) {
    std::vector<size_t> order(v.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return v[a] < v[b]; });
    std::vector<double> r(v.size());
    for (size_t i = 0; i < order.size();) {
        size_t j = i;
        while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
        for (size_t k = i; k <= j; ++k) r[order[k]] = 0.5 * double(i + j) + 1.0;
        i = j + 1;
    }
    return r;
}

} // namespace

double spearman_rho(const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() != b.size() || a.size() < 2) return NAN;
    const std::vector<double> ra = ranks(a), rb = ranks(b);
    const double mean = 0.5 * double(a.size() + 1);
    double sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        sab += (ra[i] - mean) * (rb[i] - mean);
        saa += (ra[i] - mean) * (ra[i] - mean);
        sbb += (rb[i] - mean) * (rb[i] - mean);
    }
    return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : NAN;
}

namespace {

struct Scored {
    const json* test;
    size_t page;
    double linear, display;
};

// The statement under a panel: "ρ = 0.91 over 39 tests; 14 move 3 or more places; largest: lut
// (linear #30 → display #12), …".
std::string rank_statement(const std::vector<Scored>& s) {
    std::vector<double> lin, dis;
    for (const Scored& x : s) lin.push_back(x.linear), dis.push_back(x.display);
    const std::vector<double> rl = ranks(lin), rd = ranks(dis);
    std::vector<size_t> by_move(s.size());
    std::iota(by_move.begin(), by_move.end(), 0);
    std::stable_sort(by_move.begin(), by_move.end(),
                     [&](size_t a, size_t b) { return std::fabs(rd[a] - rl[a]) > std::fabs(rd[b] - rl[b]); });
    size_t moved = 0;
    for (size_t i = 0; i < s.size(); ++i) moved += std::fabs(rd[i] - rl[i]) >= 3;
    std::string largest;
    for (size_t k = 0; k < std::min<size_t>(3, by_move.size()); ++k) {
        const size_t i = by_move[k];
        if (std::fabs(rd[i] - rl[i]) < 3) break;
        largest += fmt::format("{}{} (linear #{:g} \u2192 display #{:g})", largest.empty() ? "; largest: " : ", ",
                               test_label(*s[i].test), rl[i], rd[i]);
    }
    return fmt::format("Spearman \u03c1 = {:.2f} over {} tests; {} move 3 or more places{}", spearman_rho(lin, dis), s.size(),
                       moved, largest);
}

std::string panel(const std::string& group, const std::vector<Scored>& s, const std::string& space) {
    Chart c;
    c.id = "linear-display-";
    for (char ch : group) // runs of anything but letters and digits become one '-'
        if (std::isalnum(static_cast<unsigned char>(ch)))
            c.id += ch;
        else if (c.id.back() != '-')
            c.id += '-';
    c.title = group;
    c.note = rank_statement(s);
    c.width = 470;
    c.plot_height = 230;
    c.legend = false;
    c.x = {"mean HDR-FLIP vs the truth (linear)", false, {}, {}};
    c.y = {"mean LDR-FLIP vs the truth (" + space + ")", false, {}, {}};
    std::map<std::string, size_t> series;
    for (const Scored& x : s) {
        const std::string m = str(*x.test, "method");
        if (!series.count(m)) {
            series[m] = c.series.size();
            c.series.push_back(make_series(m, method_color(m)));
        }
        ChartPoint p;
        p.x = x.linear;
        p.y = x.display;
        p.tooltip = fmt::format("{}\nlinear HDR-FLIP {}, display LDR-FLIP {}", str(*x.test, "name"), fmt_num(x.linear),
                                fmt_num(x.display));
        p.href = "#" + test_id(x.page);
        c.series[series[m]].points.push_back(std::move(p));
    }
    return render_chart(c);
}

} // namespace

std::string display_section(const std::vector<const json*>& tests) {
    std::map<std::string, std::vector<Scored>> groups; // scene · env (and the space) -> tests scored both ways
    std::map<std::string, std::string> spaces;
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& acc = sub(*tests[i], "accuracy");
        auto lin = num(acc, "flip_mean"), dis = num(sub(acc, "display"), "flip_mean");
        if (!lin || !dis) continue;
        const json& sp = sub(sub(acc, "display"), "space");
        const std::string space = fmt::format("{} {:+g} EV, {}, {}", str(sp, "tonemap"), num(sp, "exposure").value_or(0),
                                              str(sp, "quantize"), str(sp, "target"));
        const std::string g = str(*tests[i], "scene") + " \u00b7 " + str(*tests[i], "env") + " \u00b7 " + space;
        groups[g].push_back({tests[i], i, *lin, *dis});
        spaces[g] = space;
    }
    if (groups.empty()) return "";
    std::string o = "<h2 id=\"linear-display\">Linear against display scoring</h2>\n<p class=\"meta\">The tests scored in a "
                    "display space (the suite's <code>display</code>): each test's mean FLIP against the truth in linear "
                    "HDR (HDR-FLIP over exposures; x) against the same render's mean LDR-FLIP after the render target, "
                    "exposure, tonemapper and 8-bit sRGB a player sees (y). Under each panel: how the ranking of the "
                    "tests changes between the two (Spearman's rank correlation; moves of 3 or more places).</p>\n";
    std::string panels;
    for (auto& [g, s] : groups)
        if (s.size() >= 2) panels += panel(g, s, spaces[g]);
    if (panels.empty()) // a ci run: one display test per scene, environment and space, nothing to rank
        return o + "<p class=\"meta\">No scene, environment and space has two tests scored in it.</p>\n";
    return o + "<div class=\"charts\">" + panels + "</div>\n";
}

} // namespace iblcheck::report::html
