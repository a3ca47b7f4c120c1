// The Tests tab's groups of failures (issue 32, report_html.h): a change that breaks 45 tests the
// same way reads as one group, its representative card with the viewer, and one short approve
// command; the other members are tiles folded under <details>, each opening its own card.
#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report::html {

void group_section(std::string& o, const std::vector<const json*>& tests, const FailureGroup& g, size_t k,
                   const std::string& bless_line, PageContext& ctx, const std::vector<Trend>& trends) {
    auto out = std::back_inserter(o);
    const size_t n = g.members.size();
    if (n > 1) { // a group of one is its card alone, as before
        std::string shared = g.checks;
        if (!g.metrics.empty()) {
            shared.clear();
            for (size_t i = 0; i < g.metrics.size() && i < 3; ++i) shared += (i ? ", " : "") + g.metrics[i];
            if (g.metrics.size() > 3) shared += fmt::format(", {} more checks", g.metrics.size() - 3);
        }
        if (!g.shader_change.empty()) shared += (shared.empty() ? "" : " \u00b7 ") + g.shader_change;
        std::string where;
        for (size_t i = 0; i < g.spheres.size() && i < 4; ++i) where += (i ? ", " : "") + g.spheres[i];
        if (g.spheres.size() > 4) where += fmt::format(", {} more", g.spheres.size() - 4);
        std::string variants;
        for (size_t i = 0; i < g.variants.size() && i < 4; ++i) variants += (i ? ", " : "") + g.variants[i];
        if (g.variants.size() > 4) variants += fmt::format(", {} more", g.variants.size() - 4);
        fmt::format_to(out,
                       "<section class=\"group\" id=\"g-{0}\" data-members=\"{1}\"><h2 class=\"ghead\"><span class=\"badge "
                       "v-{2}\">{1} {2}</span> {3}</h2><div class=\"meta\">{4}{5}</div>\n",
                       k, n, e(g.verdict), e(shared), where.empty() ? "" : "worst block on " + e(where),
                       variants.empty() ? "" : (where.empty() ? "" : " &middot; ") + ("options changed: " + e(variants)));
        const size_t colon = bless_line.find("): ");
        if (colon != std::string::npos)
            fmt::format_to(out,
                           "<div class=\"cmd bless-group\"><span class=\"lbl\">{}</span><pre><code>{}</code></pre><button "
                           "type=\"button\" class=\"copy\">Copy</button></div>\n",
                           e(bless_line.substr(0, colon + 1)), e(bless_line.substr(colon + 3)));
    }
    test_card(o, *tests[g.members[0]], g.members[0], ctx, trends[g.members[0]], true);
    if (n > 1) {
        fmt::format_to(out,
                       "<details class=\"gmore\"><summary>{} more in this group (click a tile to open its card)</summary>"
                       "<div class=\"tiles\">\n",
                       n - 1);
        for (size_t m = 1; m < n; ++m) {
            const size_t i = g.members[m];
            test_tile(o, *tests[i], i, ctx);
            test_card(o, *tests[i], i, ctx, trends[i], false);
        }
        o += "</div></details></section>\n";
    }
}

} // namespace iblcheck::report::html
