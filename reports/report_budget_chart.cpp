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

// The spheres' rows: one per material (metallic value) in order of appearance, as the sweep image
// lays them out (metals above, dielectrics below), so each bar stands under its sphere's column.
std::vector<std::vector<size_t>> sphere_rows(const json& spheres) {
    std::vector<double> keys;
    std::vector<std::vector<size_t>> rows;
    for (size_t i = 0; i < spheres.size(); ++i) {
        const double m = spheres[i].value("metallic", 0.0);
        const size_t k = size_t(std::find(keys.begin(), keys.end(), m) - keys.begin());
        if (k == keys.size()) keys.push_back(m), rows.emplace_back();
        rows[k].push_back(i);
    }
    return rows;
}

// Under a bar: its roughness (the row is one material; the full label is in the tooltip).
std::string column_label(const json& sphere) {
    if (sphere.contains("roughness") && sphere["roughness"].is_number()) return "r=" + fmt_num(sphere["roughness"].get<double>());
    return sphere.value("label", "");
}

// One sphere's stack: positive shares up from zero, negative ones down, in rung order.
std::string sphere_stack(const json& rungs, const json& sphere, size_t i, double x, double bar_w, double zero_y, double scale) {
    std::string o;
    double up = 0, down = 0;
    for (const json& r : rungs) {
        const double s = share_of(r, i);
        if (s == 0) continue;
        const double from = s > 0 ? up : down, to = from + s;
        (s > 0 ? up : down) = to;
        const std::string key = r.value("key", "");
        o += fmt::format(
            "<rect class=\"seg\" data-rung=\"{}\" x=\"{:.1f}\" y=\"{:.2f}\" width=\"{:.0f}\" height=\"{:.2f}\" fill=\"{}\">"
            "<title>{}: {}: {:+.4f}</title></rect>\n",
            html_escape(key), x, zero_y - std::max(from, to) * scale, bar_w, std::max(std::fabs(s) * scale, 0.5), rung_color(key),
            html_escape(sphere.value("label", "")), html_escape(r.value("label", key)), s);
    }
    return o;
}

} // namespace

std::string budget_bars_svg(const json& budget, double pitch) {
    const json& rungs = budget["rungs"];
    const json& spheres = budget["total"]["spheres"];
    const auto rows = sphere_rows(spheres);
    // One scale for every bar: the tallest positive stack and the deepest negative one.
    double top = 0, bottom = 0;
    for (size_t i = 0; i < spheres.size(); ++i) {
        double up = 0, down = 0;
        for (const json& r : rungs) (share_of(r, i) > 0 ? up : down) += share_of(r, i);
        top = std::max(top, up), bottom = std::min(bottom, down);
    }
    if (top <= 0) top = 1e-6;
    size_t cols = 1;
    for (const auto& r : rows) cols = std::max(cols, r.size());
    const double plot_h = 100, row_h = plot_h + 30, bar_w = std::max(4.0, pitch * 0.6), scale = plot_h / (top - bottom);
    const double width = std::max(double(cols) * pitch + 60, 560.0), legend_y = double(rows.size()) * row_h + 14;
    const size_t legend_rows = (rungs.size() + 3) / 4; // four rungs a legend row
    const double height = legend_y + 18 * double(legend_rows);
    const std::string env = html_escape(budget.value("env", ""));
    std::string o = fmt::format(
        "<svg class=\"chart budget\" data-chart=\"budget-{0}\" data-points=\"{1}\" width=\"{2:.0f}\" height=\"{3:.0f}\" "
        "viewBox=\"0 0 {2:.0f} {3:.0f}\" role=\"img\"><title>mean FLIP share per sphere and rung: {0}</title>\n",
        env, spheres.size(), width, height);
    for (size_t row = 0; row < rows.size(); ++row) {
        const double zero_y = double(row) * row_h + 6 + top * scale, right = double(cols) * pitch;
        std::vector<double> ticks{top, 0.0};
        if (bottom < 0) ticks.push_back(bottom);
        for (double v : ticks)
            o += fmt::format("<line x1=\"0\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" y2=\"{1:.1f}\" stroke=\"#ced4da\"/><text "
                             "x=\"{2:.1f}\" y=\"{3:.1f}\" "
                             "font-size=\"10\">{4}</text>\n",
                             right, zero_y - v * scale, right + 4, zero_y - v * scale + 3, fmt_num(v));
        for (size_t c = 0; c < rows[row].size(); ++c) {
            const size_t i = rows[row][c];
            const double x = double(c) * pitch + (pitch - bar_w) / 2;
            o += sphere_stack(rungs, spheres[i], i, x, bar_w, zero_y, scale);
            o += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"9\" text-anchor=\"middle\">{}</text>\n", x + bar_w / 2,
                             double(row) * row_h + plot_h + 20, html_escape(column_label(spheres[i])));
        }
    }
    for (size_t k = 0; k < rungs.size(); ++k) {
        const size_t legend_row = k / 4;
        const double x = double(k % 4) * 140, y = legend_y + 18 * double(legend_row);
        const std::string key = rungs[k].value("key", "");
        o +=
            fmt::format("<rect x=\"{:.0f}\" y=\"{:.0f}\" width=\"10\" height=\"10\" fill=\"{}\"/><text x=\"{:.0f}\" y=\"{:.0f}\" "
                        "font-size=\"11\">{}</text>\n",
                        x, y - 9, rung_color(key), x + 14, y, html_escape(key));
    }
    return o + "</svg>\n";
}

} // namespace iblcheck::report
