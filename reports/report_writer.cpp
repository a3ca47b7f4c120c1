// The static HTML report (issues 8, 17). See report_writer.h and results/RESULTS_FORMAT.md.
// Layout, top to bottom: the summary (counts, run facts, what changed since the baselines, the one
// command that approves every failure); tabs: Tests (failures expanded, passing tests as a grid of
// thumbnails that open their card), Charts (report_charts.cpp), History, and a table of all tests.
#include "reports/report_writer.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>

#include <fmt/format.h>

#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/shell_quote.h"
#include "metrics/flip/magma_table.h"
#include "metrics/flip/tone_mappers.h"
#include "reports/drift.h"
#include "reports/failure_groups.h"
#include "reports/nightly_findings.h"
#include "reports/report_assets.h"
#include "reports/report_html.h"
#include "reports/verdict_text.h"

namespace iblcheck::report {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace html;

namespace {

// ---- history ----
struct History {
    std::vector<const json*> runs; // oldest first, at most kMaxRuns, current run last
    static constexpr size_t kMaxRuns = 30;
};

Trend trend_for(const History& h, const std::string& test) {
    Trend t;
    if (h.runs.size() < 2) return t;
    std::vector<SparkRun> flip, frame, cost;
    std::vector<std::optional<double>> flips, costs;
    std::vector<std::optional<Spread>> spreads;
    std::vector<std::string> commits;
    double floor = 0;
    for (const json* r : h.runs) {
        const json& x = sub(sub(*r, "tests"), test.c_str());
        const std::string c = run_commit(*r), d = str(*r, "date");
        commits.push_back(c);
        flip.push_back({c, d, num(x, "flip_mean"), {}, {}});
        flips.push_back(num(x, "flip_mean"));
        floor = std::max(floor, num(x, "flip_noise").value_or(0));
        cost.push_back({c, d, num(x, "spirv_ipp"), {}, {}});
        costs.push_back(num(x, "spirv_ipp"));
        auto med = num(x, "frame_ms");
        auto lo = num(x, "frame_ms_lo"), hi = num(x, "frame_ms_hi");
        frame.push_back({c, d, med, lo, hi});
        if (med)
            spreads.push_back(Spread{lo.value_or(*med), *med, hi.value_or(*med)});
        else
            spreads.push_back(std::nullopt);
    }
    t.flip = render_sparkline("history-flip_mean", test, flip, "", accuracy_flag(flips, commits, floor));
    // The instruction count is deterministic: any change is a change (half a percent: not rounding).
    std::optional<Flag> cf;
    for (size_t i = 1, prev = 0; i < costs.size(); ++i) {
        if (!costs[i]) continue;
        if (costs[prev] && std::fabs(*costs[i] - *costs[prev]) > 0.005 * std::fabs(*costs[prev]) &&
            (!cf || std::fabs(*costs[i] - *costs[prev]) > std::fabs(cf->to - cf->from)))
            cf = Flag{i, *costs[prev], *costs[i],
                      fmt::format("{:+.1f} % at {}", 100.0 * (*costs[i] - *costs[prev]) / *costs[prev], commits[i])};
        prev = i;
    }
    t.cost = render_sparkline("history-spirv", test, cost, " instr/px", cf);
    t.frame = render_sparkline("history-frame_ms", test, frame, " ms", timing_flag(spreads, commits));
    for (const json* r : h.runs) {
        const std::string v = str(sub(sub(*r, "tests"), test.c_str()), "verdict");
        t.verdict_strip += fmt::format("<span class=\"v-{}\" title=\"{} {}: {}\"></span>", v.empty() ? "none" : e(v),
                                       e(run_commit(*r)), e(str(*r, "date")), v.empty() ? "not run" : e(v));
    }
    t.any = t.flip.points + t.frame.points + t.cost.points > 0;
    return t;
}

// The value of `flag` ("--suite ", "--shader ") in the tests' bless commands: the suite argument, and
// the run's --shader if it had one.
std::string bless_argument(const std::vector<const json*>& tests, const std::string& flag) {
    for (const json* t : tests) {
        const std::string b = str(*t, "bless_command");
        size_t p = b.find(flag);
        if (p == std::string::npos) continue;
        p += flag.size();
        return shell_word(b, p);
    }
    return "";
}

std::string js_config() {
    const float* k = flip::kToneCoefficients[int(flip::ToneMapper::aces)];
    std::string magma;
    for (int i = 0; i < 256; ++i)
        for (int c = 0; c < 3; ++c)
            magma += fmt::format("{}{}", magma.empty() ? "" : ",", int(flip::kMagma[i][c] * 255.0f + 0.5f));
    return fmt::format("window.IBLCHECK_CFG={{aces:[{},{},{},{},{},{}],magma:[{}]}};", k[0], k[1], k[2], k[3], k[4], k[5], magma);
}

// ---- the page, section by section; each appends its HTML to `o` ----

// Failures first; the original order within a verdict.
std::vector<const json*> page_order(const json& results) {
    std::vector<const json*> tests;
    for (const json& t : results["tests"]) tests.push_back(&t);
    std::stable_sort(tests.begin(), tests.end(), [](const json* a, const json* b) {
        return verdict_rank(str(*a, "verdict")) < verdict_rank(str(*b, "verdict"));
    });
    return tests;
}

std::map<std::string, int> verdict_counts(const std::vector<const json*>& tests) {
    std::map<std::string, int> counts;
    for (auto& v : verdict_order()) counts[v] = 0;
    for (const json* t : tests) counts[str(*t, "verdict")]++;
    return counts;
}

// History window: the stored runs plus this one, `current` (unless the harness appended it already).
History history_window(const std::vector<json>& history, const json& current) {
    History hist;
    std::vector<const json*> all;
    // Runs of other suites (one history file may serve several) are left out of the trend.
    for (const json& h : history)
        if (str(h, "suite").empty() || str(current, "suite").empty() || str(h, "suite") == str(current, "suite"))
            all.push_back(&h);
    if (all.empty() || str(*all.back(), "commit") != str(current, "commit") || str(*all.back(), "date") != str(current, "date"))
        all.push_back(&current);
    const size_t first = all.size() > History::kMaxRuns ? all.size() - History::kMaxRuns : 0;
    hist.runs.assign(all.begin() + long(first), all.end());
    return hist;
}

void page_head(std::string& o, const std::string& suite, std::map<std::string, int>& counts) {
    std::string title = fmt::format("iblcheck {}: ", suite.empty() ? "report" : suite);
    std::string c;
    for (auto& v : verdict_order())
        if (counts[v]) c += (c.empty() ? "" : ", ") + fmt::format("{} {}", counts[v], v);
    title += c.empty() ? "no tests" : c;
    fmt::format_to(std::back_inserter(o),
                   "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"viewport\" "
                   "content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n{}</style>\n</head>\n"
                   "<body data-check=\"pending\">\n<main>\n",
                   e(title), assets::kCss);
}

// The run's facts under the summary's heading: commit, start, total time, tests, device, driver.
void summary_facts(std::string& o, const json& results, size_t n_tests) {
    std::vector<std::string> facts;
    std::string commit = "commit <b class=\"mono\">" + e(str(results, "commit")) + "</b>";
    if (results.value("dirty", false)) commit += " <span class=\"badge dirty\">dirty</span>";
    if (!str(results, "commit").empty()) facts.push_back(commit);
    if (!str(results, "started").empty()) facts.push_back("started <b>" + e(str(results, "started")) + "</b>");
    if (auto ts = num(results, "total_s")) facts.push_back(fmt::format("total <b>{} s</b>", fmt_num(*ts)));
    facts.push_back(fmt::format("<b>{}</b> tests", n_tests));
    const json& drv = sub(results, "driver");
    if (!value_text(sub(drv, "device")).empty()) facts.push_back("device <b>" + e(value_text(sub(drv, "device"))) + "</b>");
    std::string v;
    for (auto [k, label] : {std::pair{"mesa", "Mesa"}, {"llvm", "LLVM"}, {"api", "Vulkan"}})
        if (!value_text(sub(drv, k)).empty())
            v += (v.empty() ? "" : " &middot; ") + fmt::format("{} <b>{}</b>", label, e(value_text(sub(drv, k))));
    if (!v.empty()) facts.push_back(v);
    if (!str(results, "cpu_class").empty())
        facts.push_back("CPU class <b class=\"mono\">" + e(str(results, "cpu_class")) + "</b>");
    std::string fj;
    for (auto& f : facts) fj += (fj.empty() ? "" : " &middot; ") + f;
    fmt::format_to(std::back_inserter(o), "<div class=\"facts\">{}</div>\n", fj);
}

// The summary: verdict counts (buttons that filter), the run's facts, what changed since the
// baselines, the command that ran, and the one line that approves every failure.
void summary_section(std::string& o, const json& results, const std::vector<const json*>& tests,
                     std::map<std::string, int>& counts, bool bad) {
    auto out = std::back_inserter(o);
    const std::string suite = str(results, "suite");
    fmt::format_to(out,
                   "<header class=\"summary{}\"><div class=\"hrow\"><h1>iblcheck &middot; suite {} <span class=\"badge "
                   "v-{}\">{}</span></h1><div class=\"counts\">",
                   bad ? " overall-fail" : "", e(suite.empty() ? "?" : suite), bad ? "fail" : "pass", bad ? "failed" : "passed");
    for (auto& v : verdict_order())
        fmt::format_to(out,
                       "<button type=\"button\" class=\"count v-{0}{1}\" data-verdict=\"{0}\" data-count=\"{2}\" "
                       "title=\"show only {0} (click again: all)\">{2} {0}</button>",
                       v, counts[v] ? "" : " zero", counts[v]);
    o += "</div></div>\n";
    summary_facts(o, results, tests.size());
    o += since_baselines_html(results, tests);
    if (!str(results, "command").empty())
        fmt::format_to(out,
                       "<div class=\"cmd\"><span class=\"lbl\">run</span><pre><code>{}</code></pre><button "
                       "type=\"button\" class=\"copy\">Copy</button></div>\n",
                       e(str(results, "command")));
    json arr = json::array();
    for (const json* t : tests) arr.push_back(*t);
    const std::string all_line =
        rebless_all_line(arr, bless_argument(tests, "--suite "), bless_argument(tests, "--shader "), ran_whole_suite(results));
    const size_t colon = all_line.find("): ") == std::string::npos ? std::string::npos : all_line.find("): ") + 1;
    if (colon != std::string::npos)
        fmt::format_to(out,
                       "<div class=\"cmd bless-all\"><span class=\"lbl\">{}</span><pre><code>{}</code></pre><button "
                       "type=\"button\" class=\"copy\">Copy</button></div>\n",
                       e(all_line.substr(0, colon)), e(all_line.substr(colon + 2)));
    o += "</header>\n";
}

// The tab bar, with the name filter and the verdict checkboxes.
void tabs_nav(std::string& o, size_t n_tests) {
    auto out = std::back_inserter(o);
    fmt::format_to(out,
                   "<nav class=\"tabs\"><a href=\"#tests\" class=\"on\">Tests ({})</a><a href=\"#charts\">Charts</a>"
                   "<a href=\"#history\">History</a><a href=\"#table\">Table</a><span class=\"filter\"><input "
                   "type=\"search\" id=\"filter-text\" placeholder=\"filter: lagarde, sky_sun, storage=\" aria-label=\"filter "
                   "by name\"><span class=\"vfilter\">",
                   n_tests);
    for (auto& v : verdict_order())
        fmt::format_to(
            out,
            "<label title=\"{0}\"><input type=\"checkbox\" value=\"{0}\" checked><span class=\"badge v-{0}\">{1}</span></label>",
            v, v == "missing-golden" ? "missing" : v);
    o += "</span><span id=\"filter-count\" class=\"meta\"></span></span></nav>\n";
}

// Failure modes: tests tagged failure:NAME, grouped, with each method's error.
void failure_modes(std::string& o, const std::vector<const json*>& tests) {
    std::map<std::string, std::vector<size_t>> modes;
    for (size_t i = 0; i < tests.size(); ++i)
        if (const json& tags = sub(*tests[i], "tags"); tags.is_array())
            for (const json& tag : tags)
                if (tag.is_string() && tag.get<std::string>().rfind("failure:", 0) == 0)
                    modes[tag.get<std::string>().substr(8)].push_back(i);
    if (modes.empty()) return;
    o += "<h2 id=\"failure-modes\">Failure modes</h2>\n<table class=\"grid\"><tr><th>failure mode</th><th>test</th>"
         "<th>FLIP vs the truth</th><th>verdict</th></tr>\n";
    for (auto& [mode, idx] : modes)
        for (size_t k = 0; k < idx.size(); ++k) {
            const json& t = *tests[idx[k]];
            auto acc = num(sub(t, "accuracy"), "flip_mean");
            fmt::format_to(std::back_inserter(o),
                           "<tr>{}<td><a href=\"#{}\">{}</a></td><td class=\"num\">{}</td><td><span class=\"badge "
                           "v-{}\">{}</span></td></tr>\n",
                           k == 0 ? fmt::format("<td rowspan=\"{}\"><b>{}</b></td>", idx.size(), e(mode)) : std::string(),
                           test_id(idx[k]), e(str(t, "name")), acc ? fmt_num(*acc) : std::string(), e(str(t, "verdict")),
                           e(str(t, "verdict")));
        }
    o += "</table>\n";
}

// Tests: failures expanded, then the grid of passing tests, then the failure modes.
void tests_tab(std::string& o, const std::vector<const json*>& tests, const std::vector<FailureGroup>& groups, PageContext& ctx,
               const std::vector<Trend>& trends, const std::vector<std::optional<double>>& drift) {
    o += "<section class=\"tab\" id=\"tab-tests\">\n";
    size_t n_open = 0;
    const std::string suite_arg = bless_argument(tests, "--suite "), shader_arg = bless_argument(tests, "--shader ");
    for (size_t k = 0; k < groups.size(); ++k) {
        group_section(o, tests, groups[k], k, group_bless_line(tests, groups[k], suite_arg, shader_arg), ctx, trends);
        n_open += groups[k].members.size();
    }
    // A measured run (the nightly: nothing failed, nothing has a baseline) reads as a table sorted by
    // accuracy, cost or drift; its thumbnails are folded under it.
    const bool measured =
        n_open == 0 && std::none_of(tests.begin(), tests.end(), [](const json* t) {
            return sub(*t, "comparisons").is_array() && std::any_of((*t)["comparisons"].begin(), (*t)["comparisons"].end(),
                                                                    [](const json& c) { return str(c, "kind") == "baseline"; });
        });
    if (measured && !tests.empty())
        o += fmt::format("<h2 id=\"measured\">{} tests measured <span class=\"meta\">click a numeric heading to sort; a "
                         "name opens its card</span></h2>\n",
                         tests.size()) +
             tests_table(tests, drift) + "<details class=\"gmore\"><summary>the thumbnails</summary>\n";
    if (n_open < tests.size()) {
        fmt::format_to(std::back_inserter(o),
                       "<h2 id=\"passing\">{} passing test{} <span class=\"meta\">click a tile to open it</span></h2>\n"
                       "<div class=\"tiles\">\n",
                       tests.size() - n_open, tests.size() - n_open == 1 ? "" : "s");
        for (size_t i = 0; i < tests.size(); ++i)
            if (str(*tests[i], "verdict") == "pass") {
                test_tile(o, *tests[i], i, ctx);
                test_card(o, *tests[i], i, ctx, trends[i], false);
            }
        o += "</div>\n";
    }
    if (measured && !tests.empty()) o += "</details>\n";
    failure_modes(o, tests);
    o += "</section>\n";
}

void history_tab(std::string& o, const std::vector<const json*>& tests, const History& hist, const std::vector<Trend>& trends) {
    auto out = std::back_inserter(o);
    o += "<section class=\"tab\" id=\"tab-history\">\n<h2>History</h2>\n";
    if (hist.runs.size() < 2) {
        o += "<p class=\"meta\">No history: pass <code>--history FILE</code> (JSON lines, one entry per run) to see "
             "trends.</p>\n";
    } else {
        fmt::format_to(out,
                       "<p class=\"meta\">The last {} runs, oldest left, this run right (blue). Red marks the run that "
                       "moved a figure: accuracy when it moved by more than the test's noise floor (measured by "
                       "<code>--stability</code>, else the truth's own seed noise); the instruction count (deterministic) "
                       "when it changed at all; the frame time only when a run's range of repeated timings lies wholly "
                       "outside everything measured before it. Grey bars: the range of a run's repeated timings.</p>\n",
                       hist.runs.size());
        o += "<table class=\"grid history\"><tr><th>test</th><th>verdicts</th><th>mean FLIP vs the truth</th><th>moved</th>"
             "<th>SPIR-V instr/px</th><th>moved</th><th>frame ms</th><th>moved</th></tr>\n";
        for (size_t i = 0; i < tests.size(); ++i) {
            const Trend& tr = trends[i];
            auto cell = [&](const Sparkline& s) {
                return s.points ? s.svg + " <span class=\"meta\">" + e(s.range) + "</span>" : std::string();
            };
            fmt::format_to(out,
                           "<tr class=\"filterable\" id=\"h-{0}\" data-name=\"{1}\" data-verdict=\"{2}\"><td><a "
                           "href=\"#{3}\">{1}</a></td><td><span class=\"vstrip\">{4}</span></td><td>{5}</td><td "
                           "class=\"moved-txt\">{6}</td><td>{7}</td><td class=\"moved-txt\">{8}</td><td>{9}</td><td "
                           "class=\"moved-txt\">{10}</td></tr>\n",
                           i, e(str(*tests[i], "name")), e(str(*tests[i], "verdict")), test_id(i), tr.verdict_strip,
                           cell(tr.flip), e(tr.flip.moved), cell(tr.cost), e(tr.cost.moved), cell(tr.frame), e(tr.frame.moved));
        }
        o += "</table>\n";
    }
    o += "</section>\n";
}

// The table of all tests, sortable (report_table.cpp).
void table_tab(std::string& o, const std::vector<const json*>& tests, const std::vector<std::optional<double>>& drift) {
    o += "<section class=\"tab\" id=\"tab-table\">\n<h2>All tests <span class=\"meta\">click a numeric heading to "
         "sort</span></h2>\n" +
         tests_table(tests, drift) + "</section>\n";
}

// Images the results named but the folder lacks, the footer and the scripts.
void page_end(std::string& o, const ImageStore& store, const DataStore& data) {
    if (!store.missing().empty()) {
        o += "<h2>Missing images</h2><ul class=\"mono\">";
        for (auto& m : store.missing()) fmt::format_to(std::back_inserter(o), "<li>{}</li>", e(m));
        o += "</ul>";
    }
    fmt::format_to(std::back_inserter(o),
                   "<footer>Written by <code>iblcheck report</code> from results schema iblcheck-results/1. Rebuild "
                   "it with <code>iblcheck report RESULTS.json --out DIR [--history FILE]</code>. Static and offline: "
                   "open index.html from the file system; image data in data/ ({} files).</footer>\n</main>\n"
                   "<script>{}</script>\n<script>\n{}</script>\n</body></html>\n",
                   data.files(), js_config(), assets::kJs);
}

} // namespace

namespace {
// The EXRs the tests' viewers show (report_card.cpp's comparison_html() and its fallback to the
// render alone), for DataStore::prepare().
std::vector<std::string> viewer_exrs(const std::vector<const json*>& tests) {
    std::vector<std::string> exrs;
    for (const json* t : tests) {
        bool shown = false;
        if (t->contains("comparisons") && (*t)["comparisons"].is_array())
            for (const json& c : (*t)["comparisons"]) {
                const json& imgs = sub(c, "images");
                if (str(imgs, "test").empty() && str(imgs, "golden").empty()) continue;
                shown = shown || !str(imgs, "test").empty();
                for (const char* k : {"test_exr", "golden_exr", "error_exr"}) exrs.push_back(str(imgs, k));
            }
        if (!shown) exrs.push_back(str(*t, "image_exr"));
    }
    return exrs;
}
} // namespace

void write_report(const json& results, const fs::path& results_dir, const fs::path& out_dir, const std::vector<json>& history,
                  const std::vector<json>& findings) {
    validate_results(results, (results_dir / "results.json").string());
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (!fs::is_directory(out_dir))
        throw Error(fmt::format("{}: cannot create the report folder: {}", out_dir.string(), ec.message()));
    ImageStore store(results_dir, out_dir);
    DataStore data(results_dir, out_dir);
    PageContext ctx{store, data};

    const std::vector<const json*> tests = page_order(results);
    data.prepare(viewer_exrs(tests));
    std::map<std::string, int> counts = verdict_counts(tests);
    const bool bad = counts["fail"] + counts["error"] + counts["missing-golden"] > 0;
    const json current = history_entry(results);
    const History hist = history_window(history, current);
    const std::vector<FailureGroup> groups = group_failures(tests, ran_whole_suite(results));
    std::vector<Trend> trends;
    std::vector<std::optional<double>> drift;
    for (const json* t : tests) {
        trends.push_back(trend_for(hist, str(*t, "name")));
        drift.push_back(accuracy_drift(hist.runs, str(*t, "name")));
    }

    std::string o;
    o.reserve(1 << 18);
    page_head(o, str(results, "suite"), counts);
    summary_section(o, results, tests, counts, bad);
    if (findings_wanted(results, findings)) o += findings_html(results, history, findings, store);
    tabs_nav(o, tests.size());
    tests_tab(o, tests, groups, ctx, trends, drift);
    o += "<section class=\"tab\" id=\"tab-charts\">\n" + charts_html(tests) + "</section>\n";
    history_tab(o, tests, hist, trends);
    table_tab(o, tests, drift);
    page_end(o, store, data);
    write_file_atomically(out_dir / "index.html", o, "the report"); // a reader never sees half a page
}

} // namespace iblcheck::report
