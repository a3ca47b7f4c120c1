#include "run_console.h"

#include <fmt/core.h>

#include <unistd.h>

#include <cstdio>
#include <set>

#include "reports/failure_groups.h"
#include "reports/verdict_text.h"

using nlohmann::json;

namespace iblcheck {

void print_test_line(const json& r, int n, size_t total, bool interactive, ConsoleBudget& budget) {
    std::string acc = r["accuracy"].is_object() ? fmt::format("  vs truth {:.4f}", r["accuracy"]["flip_mean"].get<double>()) : "";
    const std::string v = r["verdict"].get<std::string>();
    const std::string line = fmt::format("[{:>3}/{}] {:<15} {}{}  ({:.1f} s)", n, total, v, r["name"].get<std::string>(), acc,
                                         r["wall_s"].get<double>());
    const int k = v == "pass" ? 0 : ++budget.not_passed;
    if (v == "pass" && interactive) {
        fmt::print("\r{}\33[K", line); // progress: the next line overwrites it
    } else if (k <= ConsoleBudget::kListed) {
        fmt::print("{}{}{}\n", interactive ? "\r" : "", line, interactive ? "\33[K" : "");
        if (k <= ConsoleBudget::kDetailed)
            for (const std::string& d : verdict_details(r)) fmt::print("          {}\n", d);
        else if (k == ConsoleBudget::kDetailed + 1)
            fmt::print("          (the details of further failures: the report; groups and approve commands: below)\n");
        if (k == ConsoleBudget::kListed) fmt::print("          (further failures: counted and grouped below)\n");
    } else if (interactive) {
        fmt::print("\r{}\33[K", line);
    }
    std::fflush(stdout);
}

// The groups of failures that share a cause, each with what they share, its representative and
// one approve command; none printed for a single failure (its own lines said it all).
void print_groups(const json& R, const std::string& suite_arg, const std::string& shader_arg) {
    std::vector<const json*> tests;
    for (const json& t : R["tests"]) tests.push_back(&t);
    const std::vector<report::FailureGroup> groups = report::group_failures(tests, report::ran_whole_suite(R));
    size_t failures = 0;
    for (const auto& g : groups) failures += g.members.size();
    if (failures < 2) return;
    fmt::print("{} tests did not pass, in {} group{} (what they share; details in the report):\n", failures, groups.size(),
               groups.size() == 1 ? "" : "s");
    constexpr size_t kShown = 6;
    for (size_t i = 0; i < groups.size() && i < kShown; ++i) {
        fmt::print("  {}\n    e.g. {}\n", report::group_summary(groups[i]),
                   (*tests[groups[i].members[0]])["name"].get<std::string>());
        if (groups.size() == 1) continue; // the approve-all line below is the group's
        if (std::string b = report::group_bless_line(tests, groups[i], suite_arg, shader_arg); !b.empty())
            fmt::print("    {}\n", b);
    }
    if (groups.size() > kShown) fmt::print("  {} more groups: the report\n", groups.size() - kShown);
}

void print_run_summary(const json& R, const RunSummary& s, size_t n_tests, const RunOptions& o, const std::string& suite_arg,
                       const std::string& shader_arg) {
    // The fp16 path mediump tests took (doctor states the same rule): native float16_t, or the
    // emulation on a driver without shaderFloat16 (e.g. a CPU without F16C).
    if (isatty(STDOUT_FILENO) && !o.quiet) fmt::print("\r\33[K"); // the last progress line
    std::set<std::string> fp16;
    for (const json& r : R["tests"])
        if (r.contains("provenance") && r["provenance"].contains("fp16")) fp16.insert(r["provenance"]["fp16"].get<std::string>());
    for (const std::string& f : fp16)
        fmt::print("precision=mediump ran with {} fp16{}\n", f,
                   f == "emulated" ? " (no shaderFloat16: fp32 rounded to fp16 after every fp16 operation)" : " (float16_t)");
    fmt::print("{} tests: {} pass, {} fail, {} improved, {} missing-golden, {} error  ({:.1f} s){}\n", n_tests, s.pass, s.fail,
               s.improved, s.missing, s.error, R["total_s"].get<double>(),
               o.out_dir.empty() ? "" : "  report: " + (o.out_dir / "index.html").string());
    if (!o.history.empty()) fmt::print("history: {} (the History tab's trends)\n", o.history.string());
    print_groups(R, suite_arg, shader_arg);
    if (std::string all = rebless_all_line(R["tests"], suite_arg, shader_arg, report::ran_whole_suite(R)); !all.empty())
        fmt::print("{}\n", all);
}

} // namespace iblcheck
