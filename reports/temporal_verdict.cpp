// The specular-AA verdict of a temporal run (temporal_verdict.h).
#include "reports/temporal_verdict.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report {

using html::num;
using html::str;
using html::sub;
using nlohmann::json;

namespace {

// The temporal scene a test belongs to: scene, environment and, where the test sets it, the shading path
// (sphere_field runs through both; their figures do not compare).
std::string scene_of(const json& t) {
    std::string s = str(t, "scene") + " \u00b7 " + str(t, "env");
    const std::string shading = str(sub(t, "options"), "shading");
    return shading.empty() ? s : s + " \u00b7 shading=" + shading;
}

// The AA parameters of a test's variant ("specular_aa=toksvig,specular_aa_variance=0.02"): the variant's
// specular_aa* keys, without what the scene fixes (shading, ssaa).
std::string aa_label(const json& t, const std::string& aa) {
    const std::string v = str(t, "variant");
    std::string label;
    size_t start = 0;
    while (start <= v.size()) {
        const size_t end = std::min(v.find(',', start), v.size());
        const std::string part = v.substr(start, end - start);
        if (part.rfind("specular_aa", 0) == 0) label += (label.empty() ? "" : ",") + part;
        start = end + 1;
    }
    return label.empty() ? "specular_aa=" + aa : label;
}

std::string pct(double change) { return fmt::format("{:+.0f} %", 100 * change); }

std::string join(const std::vector<std::string>& parts) {
    std::string o;
    for (size_t i = 0; i < parts.size(); ++i) o += (i == 0 ? "" : i + 1 == parts.size() ? " and " : ", ") + parts[i];
    return o;
}

// The sentence of one scene whose variants all miss: which way each misses, and the nearest to helping.
std::string none_sentence(const std::string& scene, const std::vector<const AaOutcome*>& v) {
    std::vector<const AaOutcome*> calmer, costly;
    for (const AaOutcome* o : v) {
        if (o->flicker_change < 0) calmer.push_back(o);
        if (o->flip_change > kVerdictFlipTolerance) costly.push_back(o);
    }
    std::string s = fmt::format("{}: none of {} variant{} reduces flicker without costing accuracy.", scene, v.size(),
                                v.size() == 1 ? "" : "s");
    if (!costly.empty()) {
        const auto [lo, hi] =
            std::minmax_element(costly.begin(), costly.end(), [](auto* a, auto* b) { return a->flip_change < b->flip_change; });
        s += fmt::format(" {} of {} cost FLIP vs the truth ({} to {} of off's)", costly.size(), v.size(), pct((*lo)->flip_change),
                         pct((*hi)->flip_change));
        s += v.size() - calmer.size() > 0 ? fmt::format("; {} flicker as much as off or more", v.size() - calmer.size()) : "";
        s += ".";
    } else
        s += " Every one flickers as much as off or more.";
    if (!calmer.empty()) {
        const AaOutcome* best = *std::min_element(calmer.begin(), calmer.end(),
                                                  [](auto* a, auto* b) { return a->flicker_change < b->flicker_change; });
        s += fmt::format(" Flicker falls most with {} ({}), at FLIP {}.", best->variant, pct(best->flicker_change),
                         pct(best->flip_change));
    }
    return s;
}

} // namespace

std::vector<AaOutcome> aa_outcomes(const std::vector<const json*>& tests) {
    std::vector<AaOutcome> out;
    for (const json* tp : tests) {
        const json& t = *tp;
        const std::string aa = str(sub(t, "options"), "specular_aa");
        if (aa.empty() || aa == "off") continue;
        const json& truth = sub(sub(t, "temporal"), "truth");
        const auto fl = num(truth, "flicker"), fm = num(truth, "flip_mean");
        const auto ofl = num(sub(truth, "off"), "flicker"), ofm = num(sub(truth, "off"), "flip_mean");
        if (!fl || !fm || !ofl || !ofm || *ofl <= 0 || *ofm <= 0) continue;
        AaOutcome o;
        o.scene = scene_of(t);
        o.variant = aa_label(t, aa);
        o.test = str(t, "name");
        o.flicker_change = *fl / *ofl - 1;
        o.flip_change = *fm / *ofm - 1;
        o.helps = o.flicker_change < 0 && o.flip_change <= kVerdictFlipTolerance;
        out.push_back(std::move(o));
    }
    return out;
}

std::vector<std::string> aa_verdict_lines(const std::vector<AaOutcome>& outcomes) {
    std::vector<std::string> scenes;
    for (const AaOutcome& o : outcomes)
        if (std::find(scenes.begin(), scenes.end(), o.scene) == scenes.end()) scenes.push_back(o.scene);
    std::vector<std::string> lines;
    for (const std::string& scene : scenes) {
        std::vector<const AaOutcome*> all;
        std::vector<std::string> helpers;
        for (const AaOutcome& o : outcomes) {
            if (o.scene != scene) continue;
            all.push_back(&o);
            if (o.helps)
                helpers.push_back(fmt::format("{} (flicker {}, FLIP {})", o.variant, pct(o.flicker_change), pct(o.flip_change)));
        }
        if (helpers.empty())
            lines.push_back(none_sentence(scene, all));
        else
            lines.push_back(fmt::format("{}: {} reduce{} flicker without costing accuracy; the other {} of {} do not.", scene,
                                        join(helpers), helpers.size() == 1 ? "s" : "", all.size() - helpers.size(), all.size()));
    }
    return lines;
}

namespace {

std::string chart_id(const std::string& scene) {
    std::string id = "aa-verdict-";
    for (char ch : scene)
        if (std::isalnum(static_cast<unsigned char>(ch)))
            id += ch;
        else if (id.back() != '-')
            id += '-';
    return id;
}

// Flicker change against FLIP change vs off, one panel per scene, one colour per variant; off at (0, 0).
std::string verdict_charts(const std::vector<AaOutcome>& outcomes) {
    std::vector<Chart> charts;
    for (const AaOutcome& o : outcomes) {
        auto c = std::find_if(charts.begin(), charts.end(), [&](const Chart& x) { return x.id == chart_id(o.scene); });
        if (c == charts.end()) {
            Chart n;
            n.id = chart_id(o.scene);
            n.title = "Flicker vs FLIP change against off \u00b7 " + o.scene;
            n.note = fmt::format("vs the truth; helps: left of +{:.0f} % FLIP and below 0", 100 * kVerdictFlipTolerance);
            n.width = 470, n.plot_height = 220;
            n.x = {"FLIP vs truth: change from off (%)", false, {}, {}};
            n.y = {"flicker vs truth: change from off (%)", false, {}, {}};
            ChartSeries off = make_series("specular_aa=off", "#868e96");
            off.points.push_back(ChartPoint{0, 0, {}, {}, "off", "specular_aa=off: the origin", ""});
            n.series.push_back(std::move(off));
            charts.push_back(std::move(n));
            c = charts.end() - 1;
        }
        const std::string family = o.variant.substr(0, o.variant.find(','));
        auto s = std::find_if(c->series.begin(), c->series.end(), [&](const ChartSeries& x) { return x.name == family; });
        if (s == c->series.end()) {
            c->series.push_back(make_series(family, html::method_color(family)));
            s = c->series.end() - 1;
        }
        ChartPoint p;
        p.x = 100 * o.flip_change, p.y = 100 * o.flicker_change;
        p.label = o.helps ? "helps" : "";
        p.tooltip = fmt::format("{}\nFLIP {}, flicker {}", o.test, pct(o.flip_change), pct(o.flicker_change));
        s->points.push_back(std::move(p));
    }
    std::string o = "<div class=\"charts\">";
    for (const Chart& c : charts) o += render_chart(c);
    return o + "</div>\n";
}

} // namespace

std::string aa_verdict_html(const std::vector<const json*>& tests) {
    const std::vector<AaOutcome> outcomes = aa_outcomes(tests);
    if (outcomes.empty()) return "";
    std::string o = "<h3 id=\"aa-verdict\">Specular AA: the verdict of this run</h3>\n<ul class=\"aa-verdict\">\n";
    for (const std::string& line : aa_verdict_lines(outcomes)) o += "<li>" + html::e(line) + "</li>\n";
    o += fmt::format(
        "</ul>\n<p class=\"meta\">Against the temporal truth of every frame: a variant helps where it flickers less "
        "than specular_aa=off and its mean FLIP is at most {:.0f} % above off's. Why a widened lobe costs FLIP under a "
        "bright sun (its GGX tail, which the pixel's bounded spread of normals does not have): README, \"Specular AA, "
        "the verdict\"; the parameter sweep: scripts/specular_aa_sweep.py.</p>\n",
        100 * kVerdictFlipTolerance);
    return o + verdict_charts(outcomes);
}

} // namespace iblcheck::report
