// The findings' parts read from `iblcheck explain --json` and `iblcheck explore --json` files
// (nightly_findings.h): the largest share of error with the stacked bars, and the Pareto fronts.
#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "reports/nightly_findings.h"
#include "reports/report_html.h"

namespace iblcheck::report {

using json = nlohmann::json;
using namespace html;

namespace {

// The run's default mobile test of that scene and environment (its image is the sweep image).
const json* default_test(const json& results, const std::string& scene, const std::string& env) {
    for (const json& t : sub(results, "tests"))
        if (str(t, "method") == "mobile" && str(t, "scene") == scene && str(t, "env") == env &&
            (str(t, "variant").empty() || str(t, "variant") == "default"))
            return &t;
    return nullptr;
}

std::string budget_block(const json& b, const json& results, ImageStore& images, std::vector<std::string>& words) {
    const std::string scene = b.value("scene", ""), env = b.value("env", "");
    const double total = b["total"]["image"].value("flip", 0.0);
    const json* largest = nullptr;
    for (const json& r : b["rungs"])
        if (!largest || r["share"]["image"].value("flip", 0.0) > (*largest)["share"]["image"].value("flip", 0.0)) largest = &r;
    std::string o = fmt::format("<div class=\"budget-env\"><h4>{} under {}</h4>\n", e(scene), e(env));
    if (largest) {
        const double s = (*largest)["share"]["image"].value("flip", 0.0);
        const std::string line = fmt::format(
            "Under {}, the largest share of error is {}: {} of the mean FLIP {} ({:.0f} %); interaction between rungs {}.",
            e(env), e((*largest).value("label", "")), fmt_num(s), fmt_num(total), total > 0 ? 100 * s / total : 0.0,
            fmt_num(b["interaction"]["image"].value("flip", 0.0)));
        words.push_back(line);
        o += "<p>" + line + "</p>\n";
    }
    // The sweep image at its own size, the bars under it column for column (columns: the most
    // spheres of one material).
    double pitch = 30;
    if (const json* t = default_test(results, scene, env)) {
        const double width = num(*t, "width").value_or(0);
        std::map<double, int> per_material;
        int cols = 1;
        for (const json& s : b["total"]["spheres"]) cols = std::max(cols, ++per_material[s.value("metallic", 0.0)]);
        if (width > 0) pitch = width / cols;
        if (auto url = images.url(str(*t, "image")))
            o +=
                fmt::format("<img class=\"sweep\" src=\"{}\" alt=\"{}\" style=\"display:block;width:{:.0f}px;max-width:none\">\n",
                            e(*url), e(str(*t, "name")), width > 0 ? width : 528.0);
    }
    return o + budget_bars_svg(b, pitch) + "</div>\n";
}

std::string front_table(const json& env) {
    std::map<std::string, const json*> by_name;
    for (const json& p : env["evaluated"]) by_name[p.value("name", "")] = &p;
    std::string o = "<table class=\"grid findings-front\"><tr><th>mean FLIP</th><th>SPIR-V instr/px</th><th>fetches/px</th>"
                    "<th>texture bytes</th><th>configuration (front of FLIP against instructions)</th></tr>\n";
    for (const json& n : env["front"]["ipp"]) {
        const json* p = by_name[n.get<std::string>()];
        if (!p) continue;
        fmt::format_to(std::back_inserter(o),
                       "<tr><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td "
                       "class=\"num\">{}</td><td>{}</td></tr>\n",
                       fmt_num(p->value("flip", 0.0)), fmt_num(p->value("ipp", 0.0)), fmt_num(p->value("fetches", 0.0)),
                       fmt_num(p->value("bytes", 0.0)), e(n.get<std::string>()));
    }
    return o + "</table>\n";
}

std::string front_charts(const json& env) {
    std::string o = "<div class=\"charts-row\">";
    for (auto [key, label] : {std::pair{"ipp", "SPIR-V instructions per pixel"},
                              {"fetches", "texture fetches per pixel"},
                              {"bytes", "texture bytes"}}) {
        Chart c;
        c.id = "explore-" + env.value("env", "") + "-" + key;
        c.title = label;
        c.x.label = label, c.y.label = "mean FLIP vs the truth";
        c.pareto = true, c.width = 360, c.plot_height = 200, c.legend = false;
        ChartSeries s = make_series("rendered", "#e8590c");
        for (const json& p : env["evaluated"]) {
            ChartPoint pt;
            pt.x = p.value(key, 0.0), pt.y = p.value("flip", 0.0);
            pt.tooltip = p.value("name", "");
            if (pt.tooltip == "default" || pt.tooltip == env["best"].value("name", ""))
                pt.label = pt.tooltip == "default" ? "default" : "best";
            s.points.push_back(pt);
        }
        c.series.push_back(s);
        o += render_chart(c);
    }
    return o + "</div>\n";
}

} // namespace

std::string findings_budgets_html(const std::vector<json>& findings, const json& results, ImageStore& images,
                                  std::vector<std::string>& words) {
    std::string o;
    for (const json& f : findings)
        if (f.contains("rungs")) o += budget_block(f, results, images, words);
    if (o.empty()) {
        words.push_back("No error budget given: `iblcheck explain --json F` per environment, then `--findings F`.");
        return "";
    }
    return "<h3>Error budget: each approximation's share of the mean FLIP, per sphere <span class=\"meta\">(iblcheck explain; a "
           "colour per rung, negative shares below zero)</span></h3>\n" +
           o;
}

std::string findings_explore_html(const std::vector<json>& findings, std::vector<std::string>& words) {
    std::string o;
    for (const json& f : findings) {
        if (!f.contains("environments")) continue;
        for (const json& env : f["environments"]) {
            const json &s = env["start"], &b = env["best"];
            const std::string line = fmt::format(
                "Under {}, explore's best within +{:.0f} % instructions: {}, mean FLIP {} against the default's {} ({:+.1f} %), "
                "at {:+.1f} % "
                "instructions: {} (rendered {} of {} combinations).",
                e(env.value("env", "")), 100 * f.value("budget", 0.0), e(b.value("name", "")), fmt_num(b.value("flip", 0.0)),
                fmt_num(s.value("flip", 0.0)), -100 * env.value("flip_reduction", 0.0), 100 * (env.value("ipp_ratio", 0.0) - 1),
                env.value("target_met", false) ? "at least 30 % more accurate" : "not 30 % more accurate",
                env["evaluated"].size(), fmt_num(env.value("grid_size", 0.0)));
            words.push_back(line);
            o += fmt::format("<h4>{} under {}</h4>\n<p>{}</p>\n", e(f.value("scene", "")), e(env.value("env", "")), line) +
                 front_table(env) + front_charts(env);
        }
    }
    if (o.empty()) return "";
    return "<h3>The most accurate configuration for a cost <span class=\"meta\">(iblcheck explore: Pareto fronts of everything "
           "rendered)</span></h3>\n" +
           o;
}

} // namespace iblcheck::report
