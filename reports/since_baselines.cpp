// The summary's "what changed since the baselines" table (report_html.h). Each test's baseline
// comparison records the sidecar of the golden it was judged against ("approved": commit, date,
// shader tree hash, per-file shader hashes, driver, CPU class); the render records its own.
#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report::html {

namespace {

// What the judged baselines were blessed with (how many tests each), and how many differ from this run.
struct BlessedWith {
    std::map<std::string, int> shader, commit, driver, cpu;
    std::map<std::string, std::string> commit_date; // the latest bless date of each commit
    std::set<std::string> shader_now;               // this run's shader tree hashes
    std::map<std::string, int> files_changed;       // shader file -> tests whose baseline had it otherwise
    int judged = 0, shader_changed = 0, driver_changed = 0, cpu_changed = 0;
    int shader_changed_not_passed = 0; // of shader_changed: the tests that did not pass (what matters)
    int files_changed_not_passed = 0;  // tests that did not pass and whose shader files changed
    int files_known = 0;               // baselines whose sidecar has per-file shader hashes
};

// The shader files whose content differs between the baseline's sidecar and this render.
void count_files(BlessedWith& b, const json& was, const json& now, bool passed) {
    if (!was.is_object() || !now.is_object()) return;
    ++b.files_known;
    bool any = false;
    for (auto& [f, h] : was.items())
        if (!now.contains(f) || now[f] != h) b.files_changed[f]++, any = true;
    for (auto& [f, h] : now.items())
        if (!was.contains(f)) b.files_changed[f]++, any = true;
    b.files_changed_not_passed += any && !passed;
}

// One baseline comparison's approved facts `a`, of a test whose render has shader tree hash `sh`.
void count_approved(BlessedWith& b, const json& a, const json& t, const std::string& driver_now, const std::string& cpu_now) {
    ++b.judged;
    const std::string sh = str(sub(t, "provenance"), "shader_tree_hash");
    const std::string s = str(a, "shader_tree_hash"), cm = str(a, "commit"), d = str(a, "driver_info"), cpu = str(a, "cpu_class");
    if (!s.empty()) {
        b.shader[s]++;
        if (!sh.empty() && s != sh) ++b.shader_changed, b.shader_changed_not_passed += str(t, "verdict") != "pass";
    }
    count_files(b, sub(a, "shader_files"), sub(sub(t, "provenance"), "shader_files"), str(t, "verdict") == "pass");
    if (!cm.empty()) {
        b.commit[cm]++;
        if (b.commit_date[cm].empty() || str(a, "date") > b.commit_date[cm]) b.commit_date[cm] = str(a, "date");
    }
    if (!d.empty()) {
        b.driver[d]++;
        if (!driver_now.empty() && d != driver_now) ++b.driver_changed;
    }
    if (!cpu.empty()) {
        b.cpu[cpu]++;
        if (!cpu_now.empty() && cpu != cpu_now) ++b.cpu_changed;
    }
}

BlessedWith count_blessed(const json& results, const std::vector<const json*>& tests) {
    BlessedWith b;
    const std::string driver_now = str(sub(results, "driver"), "driver_info"), cpu_now = str(results, "cpu_class");
    for (const json* t : tests) {
        const std::string sh = str(sub(*t, "provenance"), "shader_tree_hash");
        if (!sh.empty()) b.shader_now.insert(sh);
        if (!sub(*t, "comparisons").is_array()) continue;
        for (const json& c : (*t)["comparisons"]) {
            const json& a = sub(c, "approved");
            if (str(c, "kind") != "baseline" || !a.is_object()) continue;
            count_approved(b, a, *t, driver_now, cpu_now);
        }
    }
    return b;
}

// The three most common values (cut to `cut` characters, with their date when `dates` has one)
// and how many tests each, then how many more.
std::string most_common(const std::map<std::string, int>& m, size_t cut,
                        const std::map<std::string, std::string>* dates = nullptr) {
    std::vector<std::pair<int, std::string>> v;
    for (auto& [k, n] : m) v.push_back({n, k});
    std::sort(v.rbegin(), v.rend());
    std::string s;
    for (size_t i = 0; i < v.size() && i < 3; ++i) {
        std::string k = v[i].second.substr(0, cut);
        if (dates && dates->count(v[i].second)) k += ", " + dates->at(v[i].second).substr(0, 10);
        s += (s.empty() ? "" : "; ") +
             fmt::format("<span class=\"mono\">{}</span> ({} test{})", e(k), v[i].first, v[i].first == 1 ? "" : "s");
    }
    if (v.size() > 3) s += fmt::format("; {} more", v.size() - 3);
    return s;
}

std::string change_cell(int changed, int judged) {
    return changed ? fmt::format("<td class=\"changed\">changed for {} of {}</td>", changed, judged)
                   : std::string("<td class=\"same\">same</td>");
}

// The shader tree hash (baselines blessed before per-file hashes were kept): a difference matters
// (red) only where a test that differs did not pass; one over passing tests is said, not flagged.
std::string shader_tree_cell(const BlessedWith& b) {
    if (!b.shader_changed || b.shader_changed_not_passed) return change_cell(b.shader_changed, b.judged);
    return fmt::format("<td class=\"info\">differs for {} of {}, all of which pass (some shader file changed since "
                       "they were blessed; a re-bless records which)</td>",
                       b.shader_changed, b.judged);
}

// The shader files whose content differs from what the baselines were blessed with, by file.
std::string shader_files_row(const BlessedWith& b) {
    std::string files;
    for (auto& [f, n] : b.files_changed)
        files +=
            (files.empty() ? "" : "; ") + fmt::format("<span class=\"mono\">{}</span> ({} test{})", e(f), n, n == 1 ? "" : "s");
    return fmt::format("<tr><th>shader files</th><td colspan=\"2\">{}</td>{}</tr>",
                       files.empty() ? fmt::format("as blessed ({} of {} baselines record them)", b.files_known, b.judged)
                                     : "changed since blessed: " + files,
                       files.empty() ? std::string("<td class=\"same\">same</td>")
                                     : fmt::format("<td class=\"{}\">{} file{} changed{}</td>",
                                                   b.files_changed_not_passed ? "changed" : "info", b.files_changed.size(),
                                                   b.files_changed.size() == 1 ? "" : "s",
                                                   b.files_changed_not_passed ? "" : "; every test they touch passes"));
}

// The commit row: a baseline blessed at another commit (the first 7 characters differ, "-dirty" aside).
std::string commit_row(const json& results, const BlessedWith& b) {
    const std::string now = run_commit(results);
    int changed = 0;
    for (auto& [k, n] : b.commit) {
        std::string bare = k.size() > 6 && k.substr(k.size() - 6) == "-dirty" ? k.substr(0, k.size() - 6) : k;
        if (bare.substr(0, std::min(bare.size(), size_t(7))) !=
            str(results, "commit").substr(0, std::min(size_t(7), str(results, "commit").size())))
            changed += n;
    }
    return fmt::format("<tr><th>commit</th><td>{}</td><td class=\"mono\">{}</td>{}</tr>",
                       most_common(b.commit, 12, &b.commit_date), e(now),
                       changed ? fmt::format("<td class=\"info\">{} of {} blessed at another commit (for information: "
                                             "what matters is the rows above and below)</td>",
                                             changed, b.judged)
                               : std::string("<td class=\"same\">same</td>"));
}

} // namespace

std::string since_baselines_html(const json& results, const std::vector<const json*>& tests) {
    const BlessedWith b = count_blessed(results, tests);
    if (!b.judged) return "";
    const std::string driver_now = str(sub(results, "driver"), "driver_info"), cpu_now = str(results, "cpu_class");
    std::string now_shader;
    for (auto& s : b.shader_now) now_shader += (now_shader.empty() ? "" : ", ") + s.substr(0, 16);
    std::string o = "<table class=\"since\"><tr><th>since the baselines</th><th>blessed with</th><th>this run</th><th></th></tr>";
    if (b.files_known)
        o += shader_files_row(b);
    else if (!b.shader.empty())
        o += fmt::format("<tr><th>shader tree</th><td>{}</td><td class=\"mono\">{}</td>{}</tr>", most_common(b.shader, 16),
                         e(now_shader), shader_tree_cell(b));
    if (!b.commit.empty()) o += commit_row(results, b);
    if (!b.driver.empty())
        o += fmt::format("<tr><th>driver</th><td>{}</td><td>{}</td>{}</tr>", most_common(b.driver, 60), e(driver_now),
                         change_cell(b.driver_changed, b.judged));
    if (!b.cpu.empty())
        o += fmt::format("<tr><th>CPU class</th><td>{}</td><td class=\"mono\">{}</td>{}</tr>", most_common(b.cpu, 40), e(cpu_now),
                         change_cell(b.cpu_changed, b.judged));
    o += "</table>";
    return o;
}

} // namespace iblcheck::report::html
