#include "run_profile.h"

#include <fmt/core.h>

#include <algorithm>
#include <vector>

using nlohmann::json;

namespace iblcheck {

namespace {

std::vector<std::pair<std::string, double>> by_seconds(const std::map<std::string, double>& stages) {
    std::vector<std::pair<std::string, double>> v(stages.begin(), stages.end());
    std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    return v;
}

std::map<std::string, double> stages_of(const json& test) {
    std::map<std::string, double> out;
    if (test.contains("profile") && test["profile"].is_object())
        for (const auto& [k, v] : test["profile"].items())
            if (v.is_number()) out[k] = v.get<double>();
    return out;
}

double total(const std::map<std::string, double>& stages) {
    double t = 0;
    for (const auto& [k, v] : stages) t += v;
    return t;
}

} // namespace

std::map<std::string, double> sum_test_profiles(const json& results) {
    std::map<std::string, double> sum;
    if (results.contains("tests"))
        for (const json& t : results["tests"])
            for (const auto& [k, v] : stages_of(t)) sum[k] += v;
    return sum;
}

void print_profile(const json& results, const std::map<std::string, double>& run_stages, double wall_s, int jobs,
                   size_t slowest) {
    const std::map<std::string, double> tests = sum_test_profiles(results);
    const double tests_s = total(tests);
    fmt::print("profile: {:.2f} s wall, {} worker(s); the tests {:.2f} s of worker time ({:.0f} % of {} x wall)\n", wall_s, jobs,
               tests_s, wall_s > 0 ? 100.0 * tests_s / (wall_s * jobs) : 0.0, jobs);
    fmt::print("  {:<24} {:>9} {:>7}\n", "stage (tests)", "seconds", "share");
    for (const auto& [stage, s] : by_seconds(tests))
        fmt::print("  {:<24} {:>9.2f} {:>6.1f}%\n", stage, s, tests_s > 0 ? 100.0 * s / tests_s : 0.0);
    for (const auto& [stage, s] : by_seconds(run_stages))
        fmt::print("  {:<24} {:>9.2f}  (the run's, after the tests)\n", stage, s);
    static const json none = json::array();
    std::vector<const json*> order;
    for (const json& t : results.contains("tests") ? results["tests"] : none) order.push_back(&t);
    std::stable_sort(order.begin(), order.end(),
                     [](const json* a, const json* b) { return a->value("wall_s", 0.0) > b->value("wall_s", 0.0); });
    fmt::print("  slowest tests:\n");
    for (size_t i = 0; i < std::min(slowest, order.size()); ++i) {
        std::string parts;
        const auto stages = by_seconds(stages_of(*order[i]));
        for (size_t k = 0; k < std::min<size_t>(3, stages.size()); ++k)
            parts += fmt::format("{}{} {:.2f}", k ? ", " : "", stages[k].first, stages[k].second);
        fmt::print("  {:>7.2f} s  {}  ({})\n", order[i]->value("wall_s", 0.0), order[i]->value("name", std::string()), parts);
    }
}

} // namespace iblcheck
