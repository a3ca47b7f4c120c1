#include "verdict.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "kernel/errors.h"
#include "metrics/catalog.h"

using nlohmann::json;

namespace iblcheck {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string num(double v) { return fmt::format("{:.4g}", v); }

// "+12.3 %" of `value` relative to `approved`.
std::string percent_change(double value, double approved) {
    if (approved == 0) return "from 0";
    return fmt::format("{:+.1f} %", 100.0 * (value - approved) / approved);
}

} // namespace

bool is_regression(Verdict v) { return v == Verdict::fail || v == Verdict::missing_golden; }

bool higher_is_better(std::string_view metric) {
    if (metric.rfind("accuracy.", 0) == 0) metric.remove_prefix(9); // the same figure against the truth
    const MetricInfo* m = find_metric(metric);                      // costs, temporal: lower is better
    return m && m->direction == Direction::higher_is_better;
}

Check judge_bound(const std::string& metric, double value, const Bound& bound) {
    Check c{metric, value, bound.min, bound.max, std::nullopt, Verdict::pass, ""};
    if (std::isnan(value)) {
        c.status = Verdict::fail;
        c.message = metric + " is NaN";
        return c;
    }
    // `!(v <= max)` rather than `v > max`: a NaN bound fails instead of passing.
    if (bound.max && !(value <= *bound.max)) {
        c.status = Verdict::fail;
        c.message = fmt::format("{} {} > {} (+{})", metric, num(value), num(*bound.max), num(value - *bound.max));
    } else if (bound.min && !(value >= *bound.min)) {
        c.status = Verdict::fail;
        c.message = fmt::format("{} {} < {} (-{})", metric, num(value), num(*bound.min), num(*bound.min - value));
    }
    return c;
}

Check judge_band(const std::string& metric, double value, double approved, const Band& band) {
    const double lo = approved * (1 - band.below) - band.abs, hi = approved * (1 + band.above) + band.abs;
    Check c{metric, value, lo, hi, approved, Verdict::pass, ""};
    if (std::isnan(value) || std::isnan(lo) || std::isnan(hi)) {
        c.status = Verdict::fail;
        c.message = fmt::format("{} {} or its band [{}, {}] is NaN", metric, num(value), num(lo), num(hi));
        return c;
    }
    const bool hib = higher_is_better(metric);
    const bool above = value > hi, below = value < lo;
    if (!above && !below) return c;
    const bool worse = hib ? below : above;
    c.status = worse ? Verdict::fail : Verdict::improved;
    c.message =
        worse ? fmt::format("{} {} outside [{}, {}] approved around {}", metric, num(value), num(lo), num(hi), num(approved))
              : fmt::format("{} improved: {} beyond [{}, {}] approved around {}; tighten by re-blessing", metric, num(value),
                            num(lo), num(hi), num(approved));
    return c;
}

Check judge_cost(const std::string& metric, double value, double approved, double max_growth) {
    const double hi = approved * (1 + max_growth), lo = approved * (1 - max_growth);
    Check c{metric, value, std::nullopt, hi, approved, Verdict::pass, ""};
    if (std::isnan(value) || std::isnan(approved) || std::isnan(max_growth)) {
        c.status = Verdict::fail;
        c.message = fmt::format("{} {} (approved {}) is NaN", metric, num(value), num(approved));
    } else if (!(value <= hi)) {
        c.status = Verdict::fail;
        c.message = fmt::format("{} {} > {} (approved {} +{:.0f} %): {}", metric, num(value), num(hi), num(approved),
                                100 * max_growth, percent_change(value, approved));
    } else if (value < lo) {
        c.status = Verdict::improved;
        c.message = fmt::format("{} improved: {} < {} (approved {}): {}; lock it in by re-blessing", metric, num(value), num(lo),
                                num(approved), percent_change(value, approved));
    }
    return c;
}

double metric_value(const json& metrics, const std::string& key) {
    const auto dot = key.find('.');
    if (!metrics.is_object() || dot == std::string::npos) return kNaN;
    auto group = metrics.find(key.substr(0, dot));
    if (group == metrics.end() || !group->is_object()) return kNaN;
    auto v = group->find(key.substr(dot + 1));
    return v != group->end() && v->is_number() ? v->get<double>() : kNaN;
}

namespace {
void conclude(Comparison& c) {
    std::vector<Verdict> vs;
    for (const Check& k : c.checks) {
        vs.push_back(k.status);
        if (!k.message.empty()) c.message += (c.message.empty() ? "" : "; ") + k.message;
    }
    c.verdict = overall_verdict(vs);
}
} // namespace

Comparison judge_baseline(const json& metrics, const std::map<std::string, Bound>& tolerances) {
    Comparison c;
    c.kind = "baseline";
    c.metrics = metrics;
    for (const auto& [metric, bound] : tolerances)
        if (bound.min || bound.max) c.checks.push_back(judge_bound(metric, metric_value(metrics, metric), bound));
    conclude(c);
    return c;
}

Comparison judge_size(const std::string& kind, int width, int height, int golden_width, int golden_height) {
    Comparison c;
    c.kind = kind;
    Check k;
    k.metric = "size";
    k.value = double(width) * height;
    k.status = Verdict::fail;
    k.message = fmt::format("size {}x{} but the {} golden is {}x{}", width, height, kind, golden_width, golden_height);
    c.checks.push_back(k);
    conclude(c);
    return c;
}

Comparison judge_reference(const json& metrics, const json& approved_accuracy, const std::map<std::string, Band>& bands) {
    Comparison c;
    c.kind = "reference";
    c.metrics = metrics;
    for (const auto& [metric, band] : bands) {
        if (!approved_accuracy.is_object() || !approved_accuracy.contains(metric)) continue;
        const json& a = approved_accuracy[metric];
        const double approved = a.is_number() ? a.get<double>() : kNaN;
        c.checks.push_back(judge_band("accuracy." + metric, metric_value(metrics, metric), approved, band));
    }
    conclude(c);
    return c;
}

Verdict overall_verdict(const std::vector<Verdict>& verdicts) {
    Verdict worst = Verdict::pass;
    for (Verdict v : verdicts) worst = std::max(worst, v);
    return worst;
}

size_t choose_baseline(const std::vector<Comparison>& candidates) {
    for (size_t i = 0; i < candidates.size(); ++i)
        if (!is_regression(candidates[i].verdict)) return i;
    size_t best = 0;
    double best_flip = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < candidates.size(); ++i) {
        double f = metric_value(candidates[i].metrics, "flip.mean");
        if (!std::isnan(f) && f < best_flip) best_flip = f, best = i;
    }
    return best;
}

CostJudgement judge_costs(const json& cost, const json& approved_cost, double max_growth) {
    CostJudgement out;
    out.comparison.kind = "cost";
    for (auto& [key, value] : cost.items()) {
        if (!approved_cost.is_object() || !approved_cost.contains(key) || !approved_cost[key].is_number()) {
            out.unapproved = key;
            return out;
        }
        out.comparison.checks.push_back(
            judge_cost("cost." + key, value.get<double>(), approved_cost[key].get<double>(), max_growth));
    }
    conclude(out.comparison);
    return out;
}

Verdict stop_verdict(TestStop stop) { return stop == TestStop::non_finite_render ? Verdict::fail : Verdict::error; }

Verdict stability_verdict(bool deterministic, bool flaky, bool fail_on_flaky) {
    return !deterministic || (flaky && fail_on_flaky) ? Verdict::fail : Verdict::pass;
}

std::string test_message(const std::vector<std::string>& problems, Verdict verdict,
                         const std::optional<std::string>& driver_mismatch) {
    std::string msg;
    for (const std::string& p : problems) msg += (msg.empty() ? "" : "; ") + p;
    if (driver_mismatch && verdict != Verdict::pass) msg += (msg.empty() ? "" : "; ") + *driver_mismatch;
    return msg;
}

void VerdictCounts::add(Verdict v) {
    pass += v == Verdict::pass;
    fail += v == Verdict::fail;
    improved += v == Verdict::improved;
    missing += v == Verdict::missing_golden;
    error += v == Verdict::error;
}

int run_exit_code(const VerdictCounts& c) {
    if (c.error) return kExitError;
    if (c.fail || c.missing) return kExitRegression;
    return kExitPass;
}

int repeat_exit_code(int exit_code, int verdicts_changed) {
    return verdicts_changed && exit_code == kExitPass ? kExitRegression : exit_code;
}

int bisect_exit_code(const VerdictCounts& c, bool shader_compile_error) {
    if (shader_compile_error || c.error) return kExitCannotTest;
    if (c.fail) return kExitRegression;
    return c.missing ? kExitCannotTest : kExitPass;
}

std::string_view bisect_verdict_name(int exit_code) {
    return exit_code == kExitPass ? "good" : exit_code == kExitRegression ? "bad" : "skip (125)";
}

} // namespace iblcheck
