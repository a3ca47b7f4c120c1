// The findings at the top of a nightly report (nightly_findings.h).
#include "reports/nightly_findings.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "reports/report_html.h"
#include "reports/report_writer.h"

namespace iblcheck::report {

using json = nlohmann::json;
using namespace html;

json read_findings(const std::filesystem::path& file) {
    std::ifstream f(file);
    if (!f) throw InputError(file.string() + ": cannot read the findings file");
    json j = json::parse(f, nullptr, false);
    if (j.is_discarded()) throw InputError(file.string() + ": not JSON");
    const bool budget = j.is_object() && j.contains("rungs") && j["rungs"].is_array() && j.contains("total");
    const bool explore = j.is_object() && j.value("kind", "") == "iblcheck-explore" && j.contains("environments");
    if (!budget && !explore)
        throw InputError(file.string() +
                         ": neither an `iblcheck explain --json` budget (rungs, total) nor an `iblcheck explore --json` "
                         "search (kind iblcheck-explore)");
    return j;
}

bool findings_wanted(const json& results, const std::vector<json>& findings) {
    return !findings.empty() || str(results, "suite") == "nightly";
}

namespace {

struct Measured {
    const json* t;
    double flip, ipp;
};

std::string pct_of(double a, double b) { return b > 0 ? fmt::format("{:+.1f} %", 100 * (a / b - 1)) : ""; }
// A run names the default configuration's variant "default" (older results: "").
bool is_default(const json& t) { return str(t, "variant").empty() || str(t, "variant") == "default"; }
std::string variant_name(const json& t) { return is_default(t) ? "default" : str(t, "variant"); }

// The run's tests with an accuracy against the truth, by "method scene env".
std::map<std::string, std::vector<Measured>> measured_groups(const json& results) {
    std::map<std::string, std::vector<Measured>> g;
    for (const json& t : sub(results, "tests")) {
        const auto flip = num(sub(t, "accuracy"), "flip_mean");
        if (!flip) continue;
        const double ipp = num(sub(t, "cost"), "spirv_instructions_per_pixel").value_or(0);
        g[str(t, "method") + " " + str(t, "scene") + " " + str(t, "env")].push_back({&t, *flip, ipp});
    }
    return g;
}

const Measured* default_of(const std::vector<Measured>& ms) {
    for (const Measured& m : ms)
        if (is_default(*m.t)) return &m;
    return nullptr;
}

// Accuracy per method and environment; the best and worst variant against the default.
std::string accuracy_table(const std::map<std::string, std::vector<Measured>>& groups, std::vector<std::string>& words) {
    std::string o =
        "<h3>Accuracy against the truth, per method and environment</h3>\n<table class=\"grid findings-acc\"><tr><th>method</th>"
        "<th>scene</th><th>environment</th><th>tests</th><th>default</th><th>best variant</th><th>worst variant</th></tr>\n";
    for (const auto& [key, ms] : groups) {
        const auto [lo, hi] =
            std::minmax_element(ms.begin(), ms.end(), [](const Measured& a, const Measured& b) { return a.flip < b.flip; });
        const Measured* d = default_of(ms);
        const double base = d ? d->flip : 0;
        auto cell = [&](const Measured& m) {
            return fmt::format("{} <b>{}</b> <span class=\"meta\">{}</span>", e(variant_name(*m.t)), fmt_num(m.flip),
                               pct_of(m.flip, base));
        };
        fmt::format_to(std::back_inserter(o),
                       "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td><td "
                       "class=\"num\">{}</td><td>{}</td><td>{}</td></tr>\n",
                       e(str(*ms[0].t, "method")), e(str(*ms[0].t, "scene")), e(str(*ms[0].t, "env")), ms.size(),
                       d ? fmt_num(d->flip) : "&ndash;", cell(*lo), cell(*hi));
        if (d && str(*ms[0].t, "method") == "mobile" && ms.size() > 1)
            words.push_back(
                fmt::format("{} under {}: the mobile default's mean FLIP against the truth is {}; the best variant {} ({}, {}), "
                            "the worst {} ({}).",
                            e(str(*ms[0].t, "scene")), e(str(*ms[0].t, "env")), fmt_num(base), e(variant_name(*lo->t)),
                            fmt_num(lo->flip), pct_of(lo->flip, base), e(variant_name(*hi->t)), pct_of(hi->flip, base)));
    }
    return o + "</table>\n";
}

// The best mobile test for at most each cost (SPIR-V instructions per pixel against the default's).
std::string cost_bands(const std::map<std::string, std::vector<Measured>>& groups, std::vector<std::string>& words) {
    static const std::vector<std::pair<double, std::string>> bands = {
        {1.0, "&le; the default"}, {1.1, "&le; +10 %"}, {1.5, "&le; +50 %"}, {INFINITY, "any cost"}};
    std::string o = "<h3>Best configuration per cost band <span class=\"meta\">(SPIR-V instructions per pixel against the "
                    "default's; this run's mobile tests)</span></h3>\n<table class=\"grid findings-bands\"><tr><th>scene</th>"
                    "<th>environment</th>";
    for (const auto& b : bands) o += "<th>" + b.second + "</th>";
    o += "</tr>\n";
    for (const auto& [key, ms] : groups) {
        const Measured* d = default_of(ms);
        if (str(*ms[0].t, "method") != "mobile" || !d || d->ipp <= 0) continue;
        fmt::format_to(std::back_inserter(o), "<tr><td>{}</td><td>{}</td>", e(str(*ms[0].t, "scene")), e(str(*ms[0].t, "env")));
        for (size_t k = 0; k < bands.size(); ++k) {
            const Measured* best = nullptr; // the bands are ceilings: the best for at most that cost
            for (const Measured& m : ms)
                if (m.ipp > 0 && m.ipp <= d->ipp * bands[k].first && (!best || m.flip < best->flip)) best = &m;
            o += best ? fmt::format("<td>{} <b>{}</b> <span class=\"meta\">{} FLIP, {} instr/px</span></td>",
                                    e(variant_name(*best->t)), fmt_num(best->flip), pct_of(best->flip, d->flip),
                                    pct_of(best->ipp, d->ipp))
                      : std::string("<td>&ndash;</td>");
            if (best && k == 1 && best != d)
                words.push_back(fmt::format(
                    "{} under {}: within +10 % of the default's instructions, {} is the most accurate ({} FLIP).",
                    e(str(*ms[0].t, "scene")), e(str(*ms[0].t, "env")), e(variant_name(*best->t)), pct_of(best->flip, d->flip)));
        }
        o += "</tr>\n";
    }
    return o + "</table>\n";
}

// The previous run of this suite in the history (not this run itself).
const json* previous_run(const std::vector<json>& history, const json& current) {
    for (auto it = history.rbegin(); it != history.rend(); ++it) {
        if (!str(current, "suite").empty() && !str(*it, "suite").empty() && str(*it, "suite") != str(current, "suite")) continue;
        if (str(*it, "commit") == str(current, "commit") && str(*it, "date") == str(current, "date")) continue;
        return &*it;
    }
    return nullptr;
}

// What changed since the last run: accuracy beyond the noise floor, the instruction count, tests
// added and gone.
std::string since_last_run(const json& results, const std::vector<json>& history, std::vector<std::string>& words) {
    const json current = history_entry(results);
    const json* prev = previous_run(history, current);
    std::string o = "<h3>Since the last run</h3>\n";
    if (!prev) {
        words.push_back("No earlier run to compare with (pass --history FILE).");
        return o + "<p class=\"meta\">No earlier run of this suite in the history: pass <code>--history FILE</code>.</p>\n";
    }
    const json &now = sub(current, "tests"), &then = sub(*prev, "tests");
    std::vector<std::string> rows;
    int moved = 0, cost = 0, added = 0, gone = 0;
    for (const auto& [name, t] : now.items()) {
        if (!then.contains(name)) {
            ++added;
            continue;
        }
        const json& p = then[name];
        const auto a = num(p, "flip_mean"), b = num(t, "flip_mean"), ia = num(p, "spirv_ipp"), ib = num(t, "spirv_ipp");
        const double floor = std::max(num(t, "flip_noise").value_or(0), 1e-4);
        const bool acc = a && b && std::fabs(*b - *a) > floor, ipp = ia && ib && *ia != *ib;
        moved += acc, cost += ipp;
        if (acc || ipp)
            rows.push_back(
                fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
                            e(name), acc ? fmt::format("{} &rarr; {} ({})", fmt_num(*a), fmt_num(*b), pct_of(*b, *a)) : "",
                            ipp ? fmt::format("{} &rarr; {}", fmt_num(*ia), fmt_num(*ib)) : "", acc ? fmt_num(floor) : ""));
    }
    for (const auto& [name, t] : then.items()) gone += !now.contains(name);
    const std::string line =
        fmt::format("Since the last run (commit {}, {}): {} test(s) moved in accuracy beyond their noise floor, {} "
                    "changed their instruction count, {} added, {} gone.",
                    e(str(*prev, "commit")), e(str(*prev, "date")), moved, cost, added, gone);
    words.push_back(line);
    o += "<p>" + line + "</p>\n";
    if (!rows.empty()) {
        o += "<table class=\"grid findings-changed\"><tr><th>test</th><th>mean FLIP vs the truth</th><th>SPIR-V instr/px</th>"
             "<th>noise floor</th></tr>\n";
        for (size_t i = 0; i < rows.size() && i < 20; ++i) o += rows[i];
        o += "</table>\n";
        if (rows.size() > 20) o += fmt::format("<p class=\"meta\">and {} more (History tab).</p>\n", rows.size() - 20);
    }
    return o;
}

} // namespace

std::string findings_html(const json& results, const std::vector<json>& history, const std::vector<json>& findings,
                          ImageStore& images) {
    std::vector<std::string> words;
    const auto groups = measured_groups(results);
    std::string body = findings_budgets_html(findings, results, images, words);
    body += findings_explore_html(findings, words);
    body += accuracy_table(groups, words);
    body += cost_bands(groups, words);
    body += since_last_run(results, history, words);
    std::string o = "<section class=\"findings\" id=\"findings\"><h2>What this run found</h2>\n<ul class=\"findings-words\">\n";
    for (const std::string& w : words) o += "<li>" + w + "</li>\n";
    return o + "</ul>\n" + body + "</section>\n";
}

} // namespace iblcheck::report
