#include "reports/verdict_text.h"

#include <fmt/core.h>

#include "kernel/shell_quote.h"
#include "reports/failure_groups.h"
#include "reports/report_html.h"

using nlohmann::json;

namespace iblcheck::report {

namespace {
using html::str;
bool is_num(const json& j, const char* k) { return j.is_object() && j.contains(k) && j[k].is_number(); }

// "accuracy vs truth: 0.2844 -> 0.2990 (+5.1 %), band [0.2276, 0.3146]" from the reference
// comparison's band check (approved at bless time); "" when the test has no such check.
std::string accuracy_line(const json& test) {
    if (!test.contains("comparisons") || !test["comparisons"].is_array()) return "";
    for (const json& c : test["comparisons"]) {
        if (str(c, "kind") != "reference" || !c.contains("checks")) continue;
        for (const json& k : c["checks"]) {
            if (str(k, "metric") != "accuracy.flip.mean" || !is_num(k, "value")) continue;
            const double now = k["value"].get<double>();
            if (!is_num(k, "approved")) return fmt::format("accuracy vs truth: {:.4f} (no approved figure)", now);
            const double was = k["approved"].get<double>();
            std::string band;
            if (is_num(k, "min") && is_num(k, "max"))
                band = fmt::format(", band [{:.4f}, {:.4f}]", k["min"].get<double>(), k["max"].get<double>());
            return fmt::format("accuracy vs truth: {:.4f} -> {:.4f} ({}){}", was, now,
                               was != 0 ? fmt::format("{:+.1f} %", 100.0 * (now - was) / was) : "was 0", band);
        }
    }
    const json& acc = test.value("accuracy", json());
    if (is_num(acc, "flip_mean")) return fmt::format("accuracy vs truth: {:.4f}", acc["flip_mean"].get<double>());
    return "";
}
} // namespace

std::vector<std::string> verdict_details(const json& test) {
    std::vector<std::string> out;
    const std::string v = str(test, "verdict");
    if (v == "pass" || v.empty()) return out;
    if (test.contains("comparisons") && test["comparisons"].is_array())
        for (const json& c : test["comparisons"]) {
            const std::string cv = str(c, "verdict"), kind = str(c, "kind");
            if (cv == "pass" || cv.empty()) continue;
            bool any = false;
            if (c.contains("checks"))
                for (const json& k : c["checks"])
                    if (str(k, "status") != "pass" && !str(k, "message").empty()) {
                        out.push_back(kind + ": " + str(k, "message"));
                        any = true;
                    }
            if (!any && !str(c, "message").empty()) out.push_back(kind + ": " + str(c, "message"));
            const json& wb = c.value("worst_block", json());
            if (cv == "fail" && is_num(wb, "x") && is_num(wb, "y"))
                out.push_back(fmt::format("{}: worst 16x16 block at ({},{}){}, mean {} {:.4g}", kind, wb["x"].get<int>(),
                                          wb["y"].get<int>(), str(wb, "sphere").empty() ? "" : " on " + str(wb, "sphere"),
                                          str(wb, "metric") == "display_flip" ? "LDR-FLIP on the display" : "FLIP",
                                          is_num(wb, "flip") ? wb["flip"].get<double>() : 0.0));
        }
    // Problems no image comparison holds (a render error, NaN pixels, temporal or stability checks).
    const std::string msg = str(test, "message");
    if (!msg.empty()) {
        size_t start = 0;
        while (start <= msg.size()) {
            size_t end = msg.find("; ", start);
            std::string part = msg.substr(start, end == std::string::npos ? std::string::npos : end - start);
            const bool from_comparison = part.rfind("baseline:", 0) == 0 || part.rfind("accuracy:", 0) == 0 ||
                                         part.rfind("cost.", 0) == 0 || part.rfind("worst 16x16", 0) == 0 ||
                                         part.rfind("no baseline golden", 0) == 0;
            bool shown = false;
            for (const std::string& line : out) shown = shown || line.find(part) != std::string::npos;
            if (!part.empty() && !from_comparison && !shown) out.push_back(part);
            if (end == std::string::npos) break;
            start = end + 2;
        }
    }
    if (const std::string dm = str(test, "driver_mismatch"); !dm.empty()) {
        bool shown = false;
        for (const std::string& line : out) shown = shown || line == dm;
        if (!shown) out.push_back(dm);
    }
    if (std::string acc = accuracy_line(test); !acc.empty()) out.push_back(acc);
    if ((v == "fail" || v == "missing-golden" || v == "improved") && !str(test, "bless_command").empty())
        out.push_back((v == "improved" ? "lock it in: " : "approve: ") + str(test, "bless_command"));
    return out;
}

std::string rebless_all_line(const json& tests, const std::string& suite_arg, const std::string& shader_arg, bool whole_suite) {
    std::string filter, program = "iblcheck", goldens;
    std::vector<std::string> names, all;
    int n = 0;
    for (const json& t : tests) {
        const std::string v = str(t, "verdict");
        all.push_back(str(t, "name"));
        if (v != "fail" && v != "missing-golden") continue;
        names.push_back(str(t, "name"));
        filter += (filter.empty() ? "" : "|") + glob_escape(str(t, "name"));
        // The binary the tests' own bless commands name (the one that ran: build/iblcheck after scripts/run.sh).
        const std::string b = str(t, "bless_command");
        if (n++ == 0 && b.find(" bless --suite ") != std::string::npos) program = b.substr(0, b.find(" bless --suite "));
        if (n == 1 && b.find(" --goldens ") != std::string::npos) goldens = b.substr(b.find(" --goldens ")); // the same store
    }
    if (!n) return "";
    // A whole-suite run: globs that match the failures and no other test, not every name spelt out.
    if (whole_suite) filter = covering_filter(names, all);
    return fmt::format("approve all {} failure{} (after looking at them): {} bless --suite {}{} --filter {}{}", n,
                       n == 1 ? "" : "s", program, shell_quote(suite_arg),
                       shader_arg.empty() ? "" : " --shader " + shell_quote(shader_arg), shell_quote(filter), goldens);
}

} // namespace iblcheck::report
