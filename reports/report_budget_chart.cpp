// One stacked bar per sphere of an `iblcheck explain` budget (nightly_findings.h).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "reports/nightly_findings.h"
#include "reports/svg_chart.h"

namespace iblcheck::report {

using json = nlohmann::json;

namespace {

// A colour per rung, fixed by its key so that the same rung has the same colour in every chart.
std::string rung_color(const std::string& key) {
    static const std::vector<std::pair<std::string, std::string>> fixed = {
        {"split_sum", "#1c7ed6"},   {"env_brdf_approx", "#f59f00"},   {"mip_chain", "#2f9e44"},
        {"ssaa", "#adb5bd"},        {"prefilter_samples", "#ae3ec9"}, {"diffuse", "#e8590c"},
        {"env_brdf", "#fab005"},    {"storage", "#0ca678"},           {"precision", "#495057"},
        {"specular_aa", "#d6336c"}, {"dominant_dir", "#3b5bdb"},      {"normalization", "#845ef7"}};
    for (const auto& [k, c] : fixed)
        if (k == key) return c;
    return "#868e96";
}

double share_of(const json& rung, size_t sphere) {
    const json& s = rung["share"]["spheres"];
    return sphere < s.size() ? s[sphere].value("flip", 0.0) : 0.0;
}

} // namespace

std::string budget_bars_svg(const json& budget) {
    const json& rungs = budget["rungs"];
    const json& spheres = budget["total"]["spheres"];
    const size_t n = spheres.size();
    // The scale: the tallest positive stack and the deepest negative one.
    double top = 0, bottom = 0;
    for (size_t i = 0; i < n; ++i) {
        double up = 0, down = 0;
        for (const json& r : rungs) (share_of(r, i) > 0 ? up : down) += share_of(r, i);
        top = std::max(top, up), bottom = std::min(bottom, down);
    }
    if (top <= 0) top = 1e-6;
    const double bar_w = 22, gap = 8, left = 44, plot_h = 150, legend_h = 18 * double((rungs.size() + 3) / 4);
    const double width = std::max(left + double(n) * (bar_w + gap) + 10, 560.0);
    const double scale = plot_h / (top - bottom), zero_y = 20 + top * scale, height = 20 + plot_h + 56 + legend_h;
    std::string o =
        fmt::format("<svg class=\"chart budget\" data-chart=\"budget-{}\" data-points=\"{}\" width=\"{:.0f}\" height=\"{:.0f}\" "
                    "viewBox=\"0 0 {:.0f} {:.0f}\" role=\"img\"><title>mean FLIP share per sphere and rung: {}</title>\n",
                    html_escape(budget.value("env", "")), n, width, height, width, height, html_escape(budget.value("env", "")));
    std::vector<double> ticks{top, 0.0};
    if (bottom < 0) ticks.push_back(bottom);
    for (double v : ticks) {
        const double y = zero_y - v * scale;
        o += fmt::format(
            "<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ced4da\"/><text x=\"{:.1f}\" y=\"{:.1f}\" "
            "font-size=\"10\" text-anchor=\"end\">{}</text>\n",
            left - 4, width - 6, y, y, left - 6, y + 3, fmt_num(v));
    }
    for (size_t i = 0; i < n; ++i) {
        const double x = left + double(i) * (bar_w + gap);
        double up = 0, down = 0;
        for (const json& r : rungs) {
            const double s = share_of(r, i);
            if (s == 0) continue;
            const double from = s > 0 ? up : down, to = from + s;
            (s > 0 ? up : down) = to;
            const double y0 = zero_y - std::max(from, to) * scale, h = std::fabs(s) * scale;
            const std::string key = r.value("key", "");
            o += fmt::format(
                "<rect class=\"seg\" data-rung=\"{}\" x=\"{:.1f}\" y=\"{:.2f}\" width=\"{:.0f}\" height=\"{:.2f}\" fill=\"{}\">"
                "<title>{}: {}: {:+.4f}</title></rect>\n",
                html_escape(key), x, y0, bar_w, std::max(h, 0.5), rung_color(key), html_escape(spheres[i].value("label", "")),
                html_escape(r.value("label", key)), s);
        }
        o += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"9\" transform=\"rotate(45 {:.1f} {:.1f})\">{}</text>\n",
                         x + 4, 20 + plot_h + 10, x + 4, 20 + plot_h + 10, html_escape(spheres[i].value("label", "")));
    }
    for (size_t k = 0; k < rungs.size(); ++k) {
        const double x = 10 + double(k % 4) * 140, y = 20 + plot_h + 62 + 18 * double(k / 4);
        const std::string key = rungs[k].value("key", "");
        o +=
            fmt::format("<rect x=\"{:.0f}\" y=\"{:.0f}\" width=\"10\" height=\"10\" fill=\"{}\"/><text x=\"{:.0f}\" y=\"{:.0f}\" "
                        "font-size=\"11\">{}</text>\n",
                        x, y - 9, rung_color(key), x + 14, y, html_escape(key));
    }
    return o + "</svg>\n";
}

} // namespace iblcheck::report
