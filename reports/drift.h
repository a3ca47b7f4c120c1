// What the history flags (pure: tests/test_report.cpp). A flag must mean a change, not noise:
// - accuracy (mean FLIP against the truth) is flagged when it moved by more than the test's noise
//   floor: the stability suite's measured floor of accuracy.flip.mean (Monte Carlo seeds, CPU
//   classes) when the run has one, else the reference golden's own seed noise (mean FLIP between
//   two reference renders). A fixed percentage missed a real +3 % drift and flagged noise;
// - a wall time is flagged only when a run's measured range (the median and spread of its
//   repeated timings) lies wholly outside everything the runs before it measured, and its median
//   farther from that hull than the hull is wide: a 2-5x spread between identical runs on a loaded
//   machine is not a change, nor is a new extreme of a noisy series.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace iblcheck::report {

struct Flag {
    size_t index = 0; // the run that made the change (into the series)
    double from = 0, to = 0;
    std::string text; // "+3.1 % at c4 (noise floor 0.0017)"
};

// `values`: one per run, oldest first (absent: the test did not run). The largest step between
// consecutive present values whose size exceeds `noise_floor` is flagged at the later run; when
// no single step does, a drift from the first to the last value beyond the floor is flagged at
// the last run. `commits` names the runs.
std::optional<Flag> accuracy_flag(const std::vector<std::optional<double>>& values, const std::vector<std::string>& commits,
                                  double noise_floor);

struct Spread {
    double lo = 0, median = 0, hi = 0; // of one run's repeated timings (one timing: all equal)
};

// `spreads`: one per run, oldest first. A run is flagged when its [lo, hi] lies outside the hull of
// the (at most `window`) present runs before it, its median is farther from the hull than the hull
// is wide, and at least two runs came before it; of the flagged runs the one whose median moved
// most (relative to the hull) is returned.
std::optional<Flag> timing_flag(const std::vector<std::optional<Spread>>& spreads, const std::vector<std::string>& commits,
                                size_t window = 10);

} // namespace iblcheck::report
