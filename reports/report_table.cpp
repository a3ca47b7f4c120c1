// The table of all tests (report_html.h), sortable by a click on a numeric column's heading: the
// Table tab's, and the nightly's Tests tab (issue 32: 207 thumbnails with cut titles said nothing;
// a measured run reads as a table sorted by accuracy, cost or drift since the last run).
#include <cmath>

#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report::html {

namespace {

// A numeric cell: its shown text and, in data-v, the value the sort reads ("" sorts last).
std::string num_cell(std::optional<double> x, const std::string& text) {
    return x ? fmt::format("<td class=\"num\" data-v=\"{}\">{}</td>", *x, e(text)) : std::string("<td class=\"num\"></td>");
}

} // namespace

std::optional<double> accuracy_drift(const std::vector<const json*>& runs, const std::string& test) {
    // runs: oldest first, this run last; the change against the latest earlier run that measured it.
    if (runs.size() < 2) return std::nullopt;
    const auto now = num(sub(sub(*runs.back(), "tests"), test.c_str()), "flip_mean");
    if (!now) return std::nullopt;
    for (size_t i = runs.size() - 1; i-- > 0;)
        if (auto was = num(sub(sub(*runs[i], "tests"), test.c_str()), "flip_mean"); was && *was != 0)
            return 100.0 * (*now - *was) / *was;
    return std::nullopt;
}

std::string tests_table(const std::vector<const json*>& tests, const std::vector<std::optional<double>>& drift) {
    std::string o = "<table class=\"grid overview sortable\"><thead><tr><th>verdict</th><th>test</th>"
                    "<th data-sort=\"num\" title=\"sort\">FLIP vs golden</th><th data-sort=\"num\" title=\"sort\">FLIP vs the "
                    "truth</th><th data-sort=\"num\" title=\"sort: the change of FLIP vs the truth since the last run in the "
                    "history\">drift %</th><th data-sort=\"num\" title=\"sort\">SPIR-V instr/px</th><th data-sort=\"num\" "
                    "title=\"sort\">frame ms</th><th data-sort=\"num\" title=\"sort\">precompute ms</th><th>message</th>"
                    "</tr></thead><tbody>\n";
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& t = *tests[i];
        const std::string v = str(t, "verdict");
        std::optional<double> golden_flip;
        if (sub(t, "comparisons").is_array())
            for (const json& c : t["comparisons"])
                if (!golden_flip) golden_flip = num(sub(sub(c, "metrics"), "flip"), "mean");
        auto cell = [](std::optional<double> x) { return num_cell(x, x ? fmt_num(*x) : ""); };
        const std::optional<double> d = i < drift.size() ? drift[i] : std::nullopt;
        fmt::format_to(std::back_inserter(o),
                       "<tr class=\"filterable\" data-name=\"{2}\" data-verdict=\"{0}\"><td><span class=\"badge v-{0}\">"
                       "{0}</span></td><td><a href=\"#{1}\">{2}</a></td>{3}{4}{5}{6}{7}{8}<td title=\"{10}\">{9}</td></tr>\n",
                       e(v), test_id(i), e(str(t, "name")), cell(golden_flip), cell(num(sub(t, "accuracy"), "flip_mean")),
                       num_cell(d, d ? fmt::format("{:+.1f}", *d) : ""),
                       cell(num(sub(t, "cost"), "spirv_instructions_per_pixel")), cell(num(t, "frame_ms")),
                       cell(num(t, "precompute_ms")), e(short_message(str(t, "message"))), e(str(t, "message")));
    }
    return o + "</tbody></table>\n";
}

} // namespace iblcheck::report::html
