// What the history flags (drift.h).
#include "reports/drift.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace iblcheck::report {

namespace {
std::string percent(double from, double to) {
    if (from == 0) return fmt::format("{:+.4g}", to - from);
    return fmt::format("{:+.1f} %", 100.0 * (to - from) / std::fabs(from));
}
} // namespace

std::optional<Flag> accuracy_flag(const std::vector<std::optional<double>>& values, const std::vector<std::string>& commits,
                                  double noise_floor) {
    std::vector<size_t> idx;
    for (size_t i = 0; i < values.size(); ++i)
        if (values[i] && std::isfinite(*values[i])) idx.push_back(i);
    if (idx.size() < 2) return std::nullopt;
    const double floor = std::max(noise_floor, 0.0);
    auto commit = [&](size_t i) { return i < commits.size() ? commits[i] : std::string("run ") + std::to_string(i + 1); };
    std::optional<Flag> best;
    for (size_t k = 1; k < idx.size(); ++k) {
        const double a = *values[idx[k - 1]], b = *values[idx[k]];
        if (!(std::fabs(b - a) > floor)) continue;
        if (!best || std::fabs(b - a) > std::fabs(best->to - best->from))
            best = Flag{idx[k], a, b, fmt::format("{} at {}", percent(a, b), commit(idx[k]))};
    }
    if (!best) {
        const double a = *values[idx.front()], b = *values[idx.back()];
        if (std::fabs(b - a) > floor)
            best =
                Flag{idx.back(), a, b, fmt::format("{} over {} runs since {}", percent(a, b), idx.size(), commit(idx.front()))};
    }
    if (best) best->text += floor > 0 ? fmt::format(" (noise floor {:.2g})", floor) : std::string(" (no noise floor recorded)");
    return best;
}

std::optional<Flag> timing_flag(const std::vector<std::optional<Spread>>& spreads, const std::vector<std::string>& commits,
                                size_t window) {
    std::optional<Flag> best;
    double best_move = 0;
    std::vector<size_t> seen; // present runs so far
    for (size_t i = 0; i < spreads.size(); ++i) {
        if (!spreads[i]) continue;
        const Spread& s = *spreads[i];
        if (seen.size() >= 2) {
            double lo = INFINITY, hi = -INFINITY;
            for (size_t k = seen.size() > window ? seen.size() - window : 0; k < seen.size(); ++k)
                lo = std::min(lo, spreads[seen[k]]->lo), hi = std::max(hi, spreads[seen[k]]->hi);
            // Outside the hull, and farther from it than the hull is wide: a new extreme of a noisy
            // series (likely one run in n) is not a change.
            double move = 0, from = 0;
            const double width = hi - lo;
            if (s.lo > hi && s.median - hi > width)
                move = (s.median - hi) / hi, from = hi;
            else if (s.hi < lo && lo - s.median > width)
                move = (s.median - lo) / lo, from = lo;
            if (move != 0 && std::isfinite(move) && std::fabs(move) > std::fabs(best_move)) {
                best_move = move;
                const std::string c = i < commits.size() ? commits[i] : "run " + std::to_string(i + 1);
                best = Flag{
                    i, from, s.median,
                    fmt::format("{} at {} (outside the {:.3g}\u2013{:.3g} measured before)", percent(from, s.median), c, lo, hi)};
            }
        }
        seen.push_back(i);
    }
    return best;
}

} // namespace iblcheck::report
