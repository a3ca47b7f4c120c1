// The most accurate mobile configuration for a cost (`iblcheck explore`, issue 26): a coordinate
// descent over the option space against the truth, and the Pareto fronts of everything it rendered.
//
// The search: start from the default configuration; in each pass walk the axes in their order and,
// for each, render every value with the other options at the current point; move to the value of
// least mean FLIP whose SPIR-V instructions per pixel are within the budget (default: +10 % of the
// default's); stop after a pass that moved nothing or after `passes`. Combinations are searched (a
// move keeps the earlier moves), but not all of them: the result counts and names what it did not
// try. Ties keep the current value, then the earlier value: with deterministic renders (lavapipe)
// the path, and so the front, is the same on a rerun.
//
// The fronts: over every configuration rendered (in or out of the budget), those no other beats in
// both mean FLIP and one cost (SPIR-V instructions per pixel, texture fetches per pixel, texture bytes).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "kernel/options.h"

namespace iblcheck {

struct ExploreAxis {
    std::string key;
    std::vector<std::string> values; // the first is not special: the default is the option table's
};

// A rendered configuration: the options it sets (only where they differ from the start).
struct ExplorePoint {
    OptionMap options;
    double flip = 0; // mean HDR-FLIP against the truth over the covered pixels
    double ipp = 0;  // SPIR-V instructions per pixel
    double fetches = 0;
    uint64_t bytes = 0;       // texture bytes of the prefiltered chain
    std::string name() const; // "default" or the canonical "k=v,k=v"
};

using ExploreEvaluate = std::function<ExplorePoint(const OptionMap&)>;

struct ExploreMove {
    int pass = 0;
    std::string key, from, to;
    double flip = 0, ipp = 0;
};

struct ExploreResult {
    ExplorePoint start;                  // the default configuration
    ExplorePoint best;                   // the end of the descent: least FLIP within the budget
    double ipp_budget = 0;               // instructions per pixel allowed: start.ipp * (1 + budget)
    std::vector<ExplorePoint> evaluated; // in the order rendered
    std::vector<ExploreMove> moves;
    int passes = 0;       // passes walked
    double grid_size = 0; // combinations of the axes' values
};

// Runs the descent. `budget`: the allowed increase of instructions per pixel (0.10 = +10 %).
// Throws UsageError for an empty axis, a repeated key or a value repeated on an axis.
ExploreResult explore_descent(const std::vector<ExploreAxis>& axes, const ExploreEvaluate& evaluate, double budget,
                              int max_passes);

// Indices into `points` of the Pareto front of mean FLIP against `cost` (ipp, fetches, bytes), in
// increasing cost.
enum class ExploreCost { instructions, fetches, bytes };
std::vector<size_t> explore_front(const std::vector<ExplorePoint>& points, ExploreCost cost);

// The default axes of `iblcheck explore` (the real search).
std::vector<ExploreAxis> default_explore_axes();
// Parses "key=v1|v2|v3" (an --axis), checking the key and values against the option table.
ExploreAxis parse_explore_axis(const std::string& text);

nlohmann::json explore_json(const ExploreResult& r, const std::vector<ExploreAxis>& axes);
// The terminal report: the moves, the three fronts with their configurations, what was not tried,
// and whether a configuration within the budget is at least 30 % more accurate than the default.
std::string explore_table(const nlohmann::json& j);

} // namespace iblcheck
