// The charts tab (report_html.h): small multiples, never one chart of every test. Each panel
// holds what compares (one scene and environment, or one variant family), one colour per method
// and one marker per variant family, labels that say what differs. The speed axis is the
// deterministic cost (SPIR-V instructions executed per pixel, identical on every run and CPU);
// wall time is drawn as the median and range of the repeated timings, never as a Pareto front.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <iterator>
#include <set>

#include <fmt/format.h>

#include "reports/report_html.h"
#include "reports/temporal_verdict.h"

namespace iblcheck::report::html {

namespace {

// An id from a name: runs of anything but letters and digits become one '-'.
std::string slug(const std::string& g) {
    std::string o;
    for (char ch : g) {
        if (std::isalnum(static_cast<unsigned char>(ch)))
            o += ch;
        else if (o.empty() || o.back() != '-')
            o += '-';
    }
    return o;
}
// The run's failing tests are marked on the charts (issue 32).
bool failed_now(const json& t) { return str(t, "verdict") == "fail" || str(t, "verdict") == "error"; }
std::string group_of(const json& t) { return str(t, "scene") + " \u00b7 " + str(t, "env"); }

// One marker per variant family, in order of first appearance (stable across panels): the shapes,
// then the same shapes hollow.
class Markers {
  public:
    struct Marker {
        std::string shape;
        bool hollow = false;
    };
    const Marker& of(const std::string& family) {
        auto it = map_.find(family);
        if (it != map_.end()) return it->second;
        const auto& shapes = marker_shapes();
        const size_t i = order_.size();
        order_.push_back(family);
        return map_[family] = Marker{shapes[i % shapes.size()], (i / shapes.size()) % 2 == 1};
    }
    const std::vector<std::string>& families() const { return order_; }

  private:
    std::map<std::string, Marker> map_;
    std::vector<std::string> order_;
};

// What a point's label says inside a panel that fixes scene and environment: the variant.
std::string point_label(const json& t) {
    const std::string v = str(t, "variant");
    return v.empty() || v == "default" ? str(t, "method") == "mobile" ? "default" : str(t, "method") : v;
}

// Accuracy (y: mean FLIP vs the truth) against one per-test figure (x) for one scene and
// environment: one series per method and variant family, coloured by method, marked by family.
// `x_of` gives a test's x (nullopt or <= 0: not drawn); `detail` completes a point (its tooltip's
// x part, an optional range). Returns the chart with the points' x values in `xs`.
Chart accuracy_chart(const std::string& id, const std::string& title, ChartAxis x_axis, bool pareto,
                     const std::vector<const json*>& tests, const std::vector<size_t>& page, Markers& markers,
                     const std::function<std::optional<double>(const json&)>& x_of,
                     const std::function<std::string(const json&, ChartPoint&)>& detail, std::vector<double>& xs) {
    Chart c;
    c.id = id;
    c.title = title;
    c.width = 440;
    c.plot_height = 230;
    c.legend = false;
    c.pareto = pareto;
    c.x = std::move(x_axis);
    c.y = {"mean FLIP vs the truth", false, {}, {}};
    std::map<std::pair<std::string, std::string>, size_t> series;
    for (size_t k = 0; k < tests.size(); ++k) {
        const json& t = *tests[k];
        auto f = num(sub(t, "accuracy"), "flip_mean");
        auto x = x_of(t);
        if (!f || !x || *x <= 0) continue;
        const std::string m = str(t, "method"), fam = variant_family(t);
        auto key = std::pair{m, fam};
        if (!series.count(key)) {
            series[key] = c.series.size();
            ChartSeries s = make_series(m + " \u00b7 " + fam, method_color(m));
            s.marker = markers.of(fam).shape;
            s.hollow = markers.of(fam).hollow;
            c.series.push_back(std::move(s));
        }
        ChartPoint p;
        p.x = *x;
        p.y = *f;
        p.label = point_label(t);
        p.tooltip = fmt::format("{}\n{}, mean FLIP vs the truth {}", str(t, "name"), detail(t, p), fmt_num(*f));
        p.failed = failed_now(t);
        p.href = "#" + test_id(page[k]);
        c.series[series[key]].points.push_back(std::move(p));
        xs.push_back(*x);
    }
    return c;
}

// Cost (x) against accuracy (y) for one scene and environment.
// `method`: only that method's tests (its variants side by side, on a linear axis that starts near
// them: they differ by a few percent); empty: every method (log axis when the costs span > 3x).
std::string cost_panel(const std::string& id, const std::string& title, const std::vector<const json*>& tests,
                       const std::vector<size_t>& page, Markers& markers, const std::string& method = "") {
    std::vector<double> xs;
    Chart c = accuracy_chart(
        id, title, {"SPIR-V instructions executed per pixel (deterministic)", false, {}, {}}, true, tests, page, markers,
        [&](const json& t) -> std::optional<double> {
            if (!method.empty() && str(t, "method") != method) return std::nullopt;
            return num(sub(t, "cost"), "spirv_instructions_per_pixel");
        },
        [](const json&, ChartPoint& p) { return fmt::format("{} SPIR-V instructions/pixel", fmt_num(p.x)); }, xs);
    if (xs.size() < 2) return "";
    auto [mn, mx] = std::minmax_element(xs.begin(), xs.end());
    if (method.empty()) {
        c.x.log = *mx / *mn > 3;
    } else {
        const double span = std::max(*mx - *mn, 0.02 * *mx);
        c.x.min = std::max(0.0, *mn - 0.15 * span);
        c.x.max = *mx + 0.15 * span;
    }
    return render_chart(c);
}

// Texture memory (x: the environment texture's bytes in its storage format, every level) against
// accuracy (y) for one scene and environment: the mobile storage trade-off (ASTC blocks, RGBM,
// layouts). Bytes are deterministic, so the front is drawn.
std::string bytes_panel(const std::string& id, const std::string& title, const std::vector<const json*>& tests,
                        const std::vector<size_t>& page, Markers& markers) {
    std::vector<double> xs;
    Chart c = accuracy_chart(
        id, title, {"environment texture, bytes (storage format, all levels)", true, {}, {}}, true, tests, page, markers,
        [](const json& t) { return num(t, "texture_bytes"); },
        [](const json& t, ChartPoint& p) {
            const auto texels = num(t, "texel_count");
            return fmt::format("{} bytes{}", fmt_num(p.x),
                               texels ? fmt::format(" ({} texels)", fmt_num(*texels)) : std::string());
        },
        xs);
    return xs.size() < 2 ? "" : render_chart(c);
}

// Wall time: median with the range of the repeated timings (x), accuracy (y); no front.
std::string wall_panel(const std::string& id, const std::string& title, const std::vector<const json*>& tests,
                       const std::vector<size_t>& page, Markers& markers) {
    std::vector<double> xs;
    Chart c = accuracy_chart(
        id, title, {"frame ms: median, bar: range of the repeats", true, {}, {}}, false, tests, page, markers,
        [](const json& t) { return num(t, "frame_ms"); },
        [](const json& t, ChartPoint& p) {
            const json& smp = sub(t, "frame_ms_samples");
            std::string spread = "one timing";
            if (smp.is_array() && smp.size() > 1 && smp.front().is_number() && smp.back().is_number()) {
                p.xlo = smp.front().get<double>();
                p.xhi = smp.back().get<double>();
                spread = fmt::format("median of {}, range {}\u2013{} ms", smp.size(), fmt_num(*p.xlo), fmt_num(*p.xhi));
            }
            return fmt::format("frame {} ms ({})", fmt_num(p.x), spread);
        },
        xs);
    return xs.size() < 2 ? "" : render_chart(c);
}

// Error against roughness for one environment and one variant family: the family's variants
// against the method's default; metal solid, dielectric dashed with hollow markers.
std::string roughness_panel(const std::string& id, const std::string& title, const std::vector<const json*>& members,
                            const std::vector<size_t>& page) {
    static const char* pal[] = {"#495057", "#e8590c", "#1c7ed6", "#2f9e44", "#ae3ec9", "#f59f00", "#d6336c", "#0ca678"};
    Chart c;
    c.id = id;
    c.title = title;
    c.width = 276;
    c.plot_height = 130;
    c.x = {"roughness", false, 0.0, 1.0};
    c.y = {"mean FLIP vs the truth", false, {}, {}};
    for (size_t k = 0; k < members.size(); ++k) {
        const json& t = *members[k];
        const json& ps = sub(t, "per_sphere");
        const std::string col = pal[k % std::size(pal)];
        const std::string base = point_label(t);
        ChartSeries metal = make_series(base, col, false, true);
        ChartSeries diel = make_series("", col, true, true); // one legend entry per variant
        diel.hollow = true;
        for (const json& s : ps) {
            const double m = num(s, "metallic").value_or(0);
            ChartPoint p;
            p.x = num(s, "roughness").value_or(0);
            p.y = num(s, "flip_mean").value_or(0);
            p.tooltip = fmt::format("{}\n{}: roughness {}, metallic {}, FLIP {}", str(t, "name"), str(s, "label"), fmt_num(p.x),
                                    fmt_num(m), fmt_num(p.y));
            p.failed = failed_now(t);
            p.href = "#" + test_id(page[k]);
            (m >= 0.5 ? metal : diel).points.push_back(std::move(p));
        }
        if (!metal.points.empty()) c.series.push_back(std::move(metal));
        if (!diel.points.empty()) c.series.push_back(std::move(diel));
    }
    // The legend names each variant once (solid metal, dashed dielectric is said in the note).
    c.note = "solid: metal, dashed/hollow: dielectric";
    return c.series.empty() ? "" : render_chart(c);
}

std::string legend_html(Markers& markers, const std::set<std::string>& methods) {
    std::string o = "<div class=\"legend-html\"><span class=\"meta\">colour: method</span>";
    for (const std::string& m : methods)
        o += fmt::format("<span><svg width=\"14\" height=\"14\"><circle cx=\"7\" cy=\"7\" r=\"5\" fill=\"{}\"/></svg> {}</span>",
                         method_color(m), e(m));
    o += "<span class=\"meta\">marker: what the variant changes</span>";
    for (const std::string& f : markers.families()) {
        const auto& mk = markers.of(f);
        std::string svg = marker_svg(mk.shape, 7, 7, 4.5, "#495057", "legend-marker", mk.hollow);
        o += fmt::format("<span><svg width=\"14\" height=\"14\">{}/></svg> {}</span>", svg, e(f));
    }
    o += "<span class=\"meta\">dashed staircase: Pareto front (nothing is both cheaper and more accurate than its "
         "points)</span></div>";
    return o;
}

// Cost, wall time and texture memory against accuracy: one panel per scene and environment, largest group first.
void cost_sections(std::string& o, const std::vector<const json*>& tests) {
    // Groups of one scene and environment, largest first.
    std::map<std::string, std::vector<size_t>> groups;
    for (size_t i = 0; i < tests.size(); ++i)
        if (num(sub(*tests[i], "accuracy"), "flip_mean")) groups[group_of(*tests[i])].push_back(i);
    std::vector<std::pair<std::string, std::vector<size_t>>> ordered(groups.begin(), groups.end());
    std::stable_sort(ordered.begin(), ordered.end(), [](auto& a, auto& b) { return a.second.size() > b.second.size(); });
    Markers markers;
    markers.of("default");
    std::set<std::string> methods;
    std::string cost, wall, bytes;
    for (auto& [g, idx] : ordered) {
        std::vector<const json*> gt;
        std::vector<size_t> page;
        for (size_t i : idx) {
            gt.push_back(tests[i]);
            page.push_back(i);
            methods.insert(str(*tests[i], "method"));
        }
        cost += cost_panel("cost-accuracy-" + slug(g), g, gt, page, markers);
        // The mobile variants alone: their costs differ by a few percent, invisible beside the others.
        size_t mobile = 0, others = 0;
        for (const json* t : gt)
            (str(*t, "method") == "mobile" ? mobile : others) += num(sub(*t, "cost"), "spirv_instructions_per_pixel") ? 1 : 0;
        if (mobile >= 3 && others > 0)
            cost += cost_panel("cost-accuracy-mobile-" + slug(g), g + " \u00b7 mobile variants", gt, page, markers, "mobile");
        wall += wall_panel("wall-accuracy-" + slug(g), g, gt, page, markers);
        bytes += bytes_panel("bytes-accuracy-" + slug(g), g, gt, page, markers);
    }
    o += "<h2 id=\"cost-accuracy\">Cost against accuracy</h2>\n<p class=\"meta\">One panel per scene and environment. "
         "x: SPIR-V instructions the shading dispatch executed per pixel (counted by an instrumented twin of the "
         "pass: identical on every run and CPU, the figure the cost gate checks); y: mean FLIP against the truth. "
         "Lower-left is better. Hover a point for the test, click it for its card. The CPU reference has no "
         "instruction count.</p>\n";
    o += legend_html(markers, methods);
    o += cost.empty() ? "<p class=\"meta\">No test has both an instruction count and an accuracy against the truth.</p>"
                      : "<div class=\"charts\">" + cost + "</div>\n";
    o += "<h2 id=\"wall-time\">Wall time</h2>\n<p class=\"meta\">Per-frame shading time on this machine: the point is "
         "the median of the repeated timings (the suite's <code>timing_repeats</code>), the bar their range. Wall time "
         "varies 2&ndash;5&times; between identical runs on a loaded machine, so it is shown, never gated, and no front "
         "is drawn on it.</p>\n";
    o += wall.empty() ? "<p class=\"meta\">No test has both a frame time and an accuracy against the truth.</p>"
                      : "<div class=\"charts\">" + wall + "</div>\n";
    o += "<h2 id=\"bytes-accuracy\">Texture memory against accuracy</h2>\n<p class=\"meta\">x: the environment "
         "texture the shading samples (mobile: the prefiltered chain, every level, the borders of 2D layouts included) "
         "in bytes as a device stores it (ASTC: 16 bytes a block); y: mean FLIP against the truth. The storage "
         "trade-off: lower-left is better.</p>\n";
    o += bytes.empty() ? "<p class=\"meta\">No scene and environment has two tests with a texture size and an accuracy "
                         "against the truth.</p>"
                       : "<div class=\"charts\">" + bytes + "</div>\n";
}

// Error against roughness: per scene and environment, one panel per variant family against the default.
void roughness_section(std::string& o, const std::vector<const json*>& tests) {
    auto out = std::back_inserter(o);
    // Error against roughness: per environment, one panel per variant family against the default.
    o += "<h2 id=\"roughness\">Error against roughness</h2>\n<p class=\"meta\">Per sphere, one row per scene and "
         "environment, one panel per thing a variant changes, each against the method's default (grey).</p>\n";
    std::map<std::string, std::map<std::string, std::vector<size_t>>> by_env; // group -> family -> tests
    std::map<std::string, std::map<std::string, size_t>> defaults;            // group -> method -> default test
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& t = *tests[i];
        if (!sub(t, "per_sphere").is_array() || sub(t, "per_sphere").empty()) continue;
        const std::string fam = variant_family(t), g = group_of(t);
        if (fam == "default")
            defaults[g][str(t, "method")] = i;
        else
            by_env[g][str(t, "method") == "mobile" ? fam : str(t, "method") + " " + fam].push_back(i);
        if (fam == "default" && !by_env[g].count("")) by_env[g]; // the group exists even with defaults only
    }
    bool any = false;
    for (auto& [g, fams] : by_env) {
        std::string row;
        auto panel = [&](const std::string& fam, std::vector<size_t> idx) {
            // The default of the family's method goes first (grey).
            const std::string method = str(*tests[idx.front()], "method");
            if (auto it = defaults[g].find(method); it != defaults[g].end()) idx.insert(idx.begin(), it->second);
            std::vector<const json*> members;
            std::vector<size_t> page;
            for (size_t i : idx) {
                members.push_back(tests[i]);
                page.push_back(i);
            }
            row += roughness_panel("error-roughness-" + slug(g) + "-" + slug(fam), fam, members, page);
        };
        for (auto& [fam, idx] : fams)
            if (!idx.empty()) panel(fam, idx);
        if (fams.empty() || std::all_of(fams.begin(), fams.end(), [](auto& f) { return f.second.empty(); })) {
            std::vector<size_t> d;
            for (auto& [m, i] : defaults[g]) d.push_back(i);
            if (!d.empty()) {
                std::vector<const json*> members;
                std::vector<size_t> page;
                for (size_t i : d) {
                    members.push_back(tests[i]);
                    page.push_back(i);
                }
                row += roughness_panel("error-roughness-" + slug(g), g, members, page);
            }
        }
        if (!row.empty()) {
            fmt::format_to(out, "<h3>{}</h3><div class=\"charts\">{}</div>\n", e(g), row);
            any = true;
        }
    }
    if (!any) o += "<p class=\"meta\">No test has per-sphere errors.</p>\n";
}

// Flicker against FLIP: one panel per environment, points named by what differs.
void flicker_section(std::string& o, const std::vector<const json*>& tests) {
    // Flicker against FLIP: one panel per environment, points named by what differs.
    o += "<h2 id=\"temporal\">Flicker against FLIP (temporal tests)</h2>\n";
    o += aa_verdict_html(tests); // which specular_aa variant helps, from this run's truth figures
    std::map<std::string, Chart> flick;
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& t = *tests[i];
        const json& tp = sub(t, "temporal");
        auto fl = num(tp, "flicker");
        auto fm = num(tp, "flip_mean");
        if (!fm) fm = num(sub(t, "accuracy"), "flip_mean");
        if (!fl || !fm) continue;
        const std::string g = group_of(t);
        Chart& c = flick[g];
        if (c.id.empty()) {
            c.id = "flicker-flip-" + slug(g);
            c.title = "Flicker vs mean FLIP \u00b7 " + g;
            c.note = "lower-left is better; label: what differs";
            c.width = 470;
            c.plot_height = 220;
            c.x = {"mean FLIP vs the reference sequence", false, {}, {}};
            c.y = {"flicker", false, {}, {}};
        }
        const std::string m = str(t, "method").empty() ? "other" : str(t, "method");
        auto it = std::find_if(c.series.begin(), c.series.end(), [&](const ChartSeries& s) { return s.name == m; });
        if (it == c.series.end()) {
            c.series.push_back(make_series(m, method_color(m)));
            it = c.series.end() - 1;
        }
        ChartPoint p;
        p.x = *fm;
        p.y = *fl;
        p.label = test_label(t) + " \u00b7 " + str(t, "env"); // method, variant and environment
        p.tooltip = fmt::format("{}\nFLIP = {}, flicker = {}", str(t, "name"), fmt_num(*fm), fmt_num(*fl));
        p.failed = failed_now(t);
        p.href = "#" + test_id(i);
        it->points.push_back(std::move(p));
    }
    if (flick.empty())
        o += "<p class=\"meta\">No temporal test in this run.</p>\n";
    else {
        o += "<div class=\"charts\">";
        for (auto& [g, c] : flick) o += render_chart(c);
        o += "</div>\n";
    }
}

} // namespace

std::string charts_html(const std::vector<const json*>& tests) {
    std::string o;
    cost_sections(o, tests);
    o += display_section(tests);
    roughness_section(o, tests);
    flicker_section(o, tests);
    return o;
}

} // namespace iblcheck::report::html
