#include "reports/failure_groups.h"

#include <fnmatch.h>

#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "kernel/name_filter.h"
#include "kernel/shell_quote.h"
#include "reports/report_html.h"

using nlohmann::json;

namespace iblcheck::report {

namespace {

using html::str;
using html::sub;

// "baseline; reference": the comparisons that did not pass, or for a test without one (an error, a
// missing golden) the first part of its message, cut at the first digit (values differ, causes not).
// Which metrics failed is not part of the key: one constant fails ssim.mean on some of its tests and
// not on others; the group counts them instead (failing_metrics).
std::string failing_kinds(const json& t) {
    std::string out;
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (str(c, "verdict") != "pass" && !str(c, "verdict").empty()) out += (out.empty() ? "" : "; ") + str(c, "kind");
    if (out.empty()) {
        std::string m = str(t, "message").substr(0, str(t, "message").find("; "));
        out = m.substr(0, m.find_first_of("0123456789"));
    }
    return out;
}

// "baseline flip.mean", one per check that did not pass.
std::vector<std::string> failing_metrics(const json& t) {
    std::vector<std::string> out;
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (sub(c, "checks").is_array() && str(c, "verdict") != "pass")
                for (const json& k : c["checks"])
                    if (str(k, "status") != "pass" && !str(k, "status").empty())
                        out.push_back(str(c, "kind") + " " + str(k, "metric"));
    return out;
}

// What changed in the shaders since the test's baseline was blessed: by file where both the
// sidecar and the render recorded per-file hashes, else the tree hash; "" when nothing did.
std::string shader_change(const json& t) {
    const json& now = sub(t, "provenance");
    if (!sub(t, "comparisons").is_array()) return "";
    for (const json& c : t["comparisons"]) {
        const json& a = sub(c, "approved");
        if (str(c, "kind") != "baseline" || !a.is_object()) continue;
        const json &fa = sub(a, "shader_files"), &fn = sub(now, "shader_files");
        if (fa.is_object() && fn.is_object()) {
            std::set<std::string> files;
            for (auto& [f, h] : fa.items())
                if (!fn.contains(f) || fn[f] != h) files.insert(f);
            for (auto& [f, h] : fn.items())
                if (!fa.contains(f)) files.insert(f);
            std::string s;
            for (const std::string& f : files) s += (s.empty() ? "" : ", ") + f;
            return s.empty() ? "" : s + " changed";
        }
        const std::string was = str(a, "shader_tree_hash"), is = str(now, "shader_tree_hash");
        if (!was.empty() && !is.empty() && was != is) return "shader tree " + was.substr(0, 8) + " -> " + is.substr(0, 8);
    }
    return "";
}

double baseline_flip(const json& t) {
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (str(c, "kind") == "baseline" && sub(sub(sub(c, "metrics"), "flip"), "mean").is_number())
                return c["metrics"]["flip"]["mean"].get<double>();
    return -1;
}

std::string worst_sphere(const json& t) {
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (std::string s = str(sub(c, "worst_block"), "sphere"); !s.empty()) return s;
    return "";
}

std::string option_keys(const json& t) {
    std::string k;
    if (sub(t, "options").is_object())
        for (auto& [key, v] : t["options"].items()) k += (k.empty() ? "" : "+") + key;
    return k.empty() ? "default" : k;
}

// "metal r=0.3 (12)", most common first.
std::vector<std::string> ranked_counts(const std::map<std::string, int>& m) {
    std::vector<std::pair<int, std::string>> v;
    for (auto& [k, n] : m)
        if (!k.empty()) v.push_back({-n, k});
    std::sort(v.begin(), v.end());
    std::vector<std::string> out;
    for (auto& [n, k] : v) out.push_back(fmt::format("{} ({})", k, -n));
    return out;
}

bool glob_hits(const std::string& glob, const std::string& name) { return ::fnmatch(glob.c_str(), name.c_str(), 0) == 0; }

std::vector<std::string> split_at(const std::string& s, char sep) {
    std::vector<std::string> out(1);
    for (char c : s)
        if (c == sep)
            out.emplace_back();
        else
            out.back() += c;
    return out;
}

// The globs tried for one name: each subset of its parts (but not all) replaced by '*', neighbouring
// '*'s merged, and '*KEY=VALUE*' and '*KEY=*' for each option of its variant.
std::vector<std::string> candidate_globs(const std::string& name) {
    std::vector<std::string> parts = split_at(name, '.');
    std::vector<std::string> out;
    if (parts.size() > 6) return {glob_escape(name)}; // an environment file's name with dots: no structure to use
    for (unsigned mask = 0; mask < (1u << parts.size()) - 1; ++mask) {
        std::string g;
        for (size_t i = 0; i < parts.size(); ++i) {
            const bool star = (mask >> i) & 1;
            if (star && i && (mask >> (i - 1)) & 1) continue; // "*.*" is "*": '*' matches dots too
            g += (i ? "." : "") + (star ? std::string("*") : glob_escape(parts[i]));
        }
        out.push_back(g);
    }
    for (const std::string& part : parts) // "*dominant_dir=lagarde*" and "*dominant_dir=*"
        for (const std::string& opt : split_at(part, ','))
            if (size_t eq = opt.find('='); eq != std::string::npos) {
                out.push_back("*" + glob_escape(opt) + "*");
                out.push_back("*" + glob_escape(opt.substr(0, eq + 1)) + "*");
            }
    return out;
}

} // namespace

namespace {

// Greedy cover: globs (from candidate_globs of the names in `cover`) that together match every name
// of `cover` and none of `avoid`; each step takes the glob that matches the most names left, then
// the one with the fewest '*' (the most telling), then the shortest.
std::vector<std::string> greedy_cover(const std::set<std::string>& cover, const std::vector<std::string>& avoid) {
    const std::set<std::string> bad(avoid.begin(), avoid.end());
    std::set<std::string> left = cover;
    std::vector<std::string> chosen;
    const auto stars = [](const std::string& x) { return std::count(x.begin(), x.end(), '*'); };
    while (!left.empty()) {
        std::string best;
        size_t best_n = 0;
        std::set<std::string> tried;
        for (const std::string& name : left)
            for (const std::string& g : candidate_globs(name)) {
                if (!tried.insert(g).second) continue;
                if (std::any_of(bad.begin(), bad.end(), [&](const std::string& a) { return glob_hits(g, a); })) continue;
                const size_t n =
                    size_t(std::count_if(left.begin(), left.end(), [&](const std::string& a) { return glob_hits(g, a); }));
                if (n > best_n || (n == best_n && std::make_pair(stars(g), g.size()) < std::make_pair(stars(best), best.size())))
                    best = g, best_n = n;
            }
        if (best_n == 0) best = glob_escape(*left.begin()); // unreachable: a name's own glob is a candidate
        for (auto it = left.begin(); it != left.end();) it = glob_hits(best, *it) ? left.erase(it) : std::next(it);
        chosen.push_back(best);
    }
    return chosen;
}

std::string join_globs(const std::vector<std::string>& v, const std::string& prefix = "") {
    std::string f;
    for (const std::string& g : v) f += (f.empty() ? "" : "|") + prefix + g;
    return f;
}

// Fewer globs, then fewer '*' (a name spelt out reads best), then shorter.
std::tuple<long, long, size_t> filter_rank(const std::string& f) {
    return {std::count(f.begin(), f.end(), '|'), std::count(f.begin(), f.end(), '*'), f.size()};
}

} // namespace

std::string covering_filter(const std::vector<std::string>& members, const std::vector<std::string>& all) {
    if (members.empty()) return "";
    const std::set<std::string> in(members.begin(), members.end());
    std::vector<std::string> out_names;
    for (const std::string& a : all)
        if (!in.count(a)) out_names.push_back(a);
    std::string best = join_globs(greedy_cover(in, out_names));
    // Or one glob over every member and `!` globs for the other names it catches (52 failures of
    // one constant: every mobile test but the ones that pass, "mobile.*|!*mip_mapping=*|!...").
    std::set<std::string> tried;
    for (const std::string& g : candidate_globs(members.front())) {
        if (!tried.insert(g).second || !std::all_of(members.begin(), members.end(), [&](auto& m) { return glob_hits(g, m); }))
            continue;
        std::set<std::string> caught;
        for (const std::string& a : out_names)
            if (glob_hits(g, a)) caught.insert(a);
        const std::string f = g + (caught.empty() ? "" : "|" + join_globs(greedy_cover(caught, members), "!"));
        if (filter_rank(f) < filter_rank(best)) best = f;
    }
    for (const std::string& a : all) // what the harness will select: exactly the members
        if (name_filter_match(best, a) != (in.count(a) > 0)) return join_globs(greedy_cover(in, out_names));
    return best;
}

bool ran_whole_suite(const json& results) {
    const std::string cmd = str(results, "command"), shard = str(results, "shard");
    return cmd.find(" --filter") == std::string::npos && cmd.find(" --shard") == std::string::npos &&
           (shard.empty() || shard == "0/1");
}

std::vector<FailureGroup> group_failures(const std::vector<const json*>& tests, bool run_is_whole_suite) {
    std::map<std::tuple<std::string, std::string, std::string>, FailureGroup> by_key;
    std::map<std::tuple<std::string, std::string, std::string>, std::pair<std::map<std::string, int>, std::map<std::string, int>>>
        tallies;
    std::map<std::tuple<std::string, std::string, std::string>, std::map<std::string, int>> metric_tally;
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& t = *tests[i];
        const std::string v = str(t, "verdict");
        if (v == "pass" || v.empty()) continue;
        const auto key = std::make_tuple(v, failing_kinds(t), shader_change(t));
        FailureGroup& g = by_key[key];
        g.verdict = v;
        g.checks = std::get<1>(key);
        g.shader_change = std::get<2>(key);
        g.members.push_back(i);
        tallies[key].first[worst_sphere(t)]++;
        for (const std::string& m : failing_metrics(t)) metric_tally[key][m]++;
        tallies[key].second[option_keys(t)]++;
    }
    std::vector<std::string> all;
    for (const json* t : tests) all.push_back(str(*t, "name"));

    std::vector<FailureGroup> out;
    for (auto& [key, g] : by_key) {
        // The representative: the largest change against its baseline (the clearest picture of the cause).
        std::stable_sort(g.members.begin(), g.members.end(),
                         [&](size_t a, size_t b) { return baseline_flip(*tests[a]) > baseline_flip(*tests[b]); });
        g.spheres = ranked_counts(tallies[key].first);
        g.variants = ranked_counts(tallies[key].second);
        g.metrics = ranked_counts(metric_tally[key]);
        std::vector<std::string> names;
        for (size_t m : g.members) names.push_back(all[m]);
        if (run_is_whole_suite) {
            g.filter = covering_filter(names, all);
        } else {
            for (const std::string& n : names) g.filter += (g.filter.empty() ? "" : "|") + glob_escape(n);
        }
        out.push_back(std::move(g));
    }
    std::stable_sort(out.begin(), out.end(), [](const FailureGroup& a, const FailureGroup& b) {
        auto rank = [](const std::string& v) { return v == "fail" ? 0 : v == "error" ? 1 : v == "missing-golden" ? 2 : 3; };
        return std::make_pair(rank(a.verdict), -long(a.members.size())) <
               std::make_pair(rank(b.verdict), -long(b.members.size()));
    });
    return out;
}

std::string group_bless_line(const std::vector<const json*>& tests, const FailureGroup& g, const std::string& suite_arg,
                             const std::string& shader_arg) {
    if (g.verdict != "fail" && g.verdict != "missing-golden" && g.verdict != "improved") return "";
    std::string program = "iblcheck", goldens;
    const std::string b = g.members.empty() ? "" : str(*tests[g.members[0]], "bless_command");
    if (b.empty()) return "";
    // The binary and golden store the members' own bless commands name (the ones that ran).
    if (b.find(" bless --suite ") != std::string::npos) program = b.substr(0, b.find(" bless --suite "));
    if (b.find(" --goldens ") != std::string::npos) goldens = b.substr(b.find(" --goldens "));
    const size_t n = g.members.size();
    return fmt::format("{} {} {}{} (after looking at them): {} bless --suite {}{} --filter {}{}",
                       g.verdict == "improved" ? "lock in" : "approve", n, g.verdict == "improved" ? "improvement" : "failure",
                       n == 1 ? "" : "s", program, shell_quote(suite_arg),
                       shader_arg.empty() ? "" : " --shader " + shell_quote(shader_arg), shell_quote(g.filter), goldens);
}

std::string group_summary(const FailureGroup& g) {
    std::string s = fmt::format("{} {}", g.members.size(), g.verdict);
    if (!g.metrics.empty()) {
        s += " \u00b7 ";
        for (size_t i = 0; i < g.metrics.size() && i < 3; ++i) s += (i ? ", " : "") + g.metrics[i];
        if (g.metrics.size() > 3) s += fmt::format(", {} more", g.metrics.size() - 3);
    } else if (!g.checks.empty()) {
        s += " \u00b7 " + g.checks;
    }
    if (!g.shader_change.empty()) s += " \u00b7 " + g.shader_change;
    if (!g.spheres.empty()) {
        s += " \u00b7 worst on ";
        for (size_t i = 0; i < g.spheres.size() && i < 3; ++i) s += (i ? ", " : "") + g.spheres[i];
        if (g.spheres.size() > 3) s += fmt::format(", {} more", g.spheres.size() - 3);
    }
    return s;
}

} // namespace iblcheck::report
