// Globally adaptive refinement: the strategy of QUADPACK's QAG (Piessens et al. 1983), for regions
// that split into (up to) four. Every region carries two estimates of its integral: a coarse one (its
// own rule) and a fine one (the sum of its children's rules); the truth keeps the fine one and
// |fine − coarse| (rgb_size) is the region's error indicator — the error of the coarse estimate, which
// bounds the fine one's error wherever the rule converges (the fine error is then a fraction of it).
// The region with the largest indicator is split until the indicators sum to at most
// tolerance·(|estimate| + floor), or no region may be split, or the split budget is spent. A region
// may be *forced* (split first, whatever its indicator): the callers force regions whose rules could
// not see a feature smaller than the region (a narrow BRDF lobe inside an environment cell).
// Deterministic: the same regions are split in the same order for the same input.
#pragma once
#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

#include "renderers/reference/quadrature/truth_math.h"

namespace iblcheck::truth {

struct RefineOutcome {
    double value[3] = {0, 0, 0}; // Σ fine estimates of the final regions
    double error = 0;            // Σ indicators of the final regions (the stated error of `value`)
    size_t regions = 0;          // final regions
    size_t splits = 0;
    bool budget_hit = false;
};

// Region must have: double fine[3]; double indicator; bool forced; bool splittable.
// `pool` holds the initial regions (and is used as the region store); split(const Region&,
// std::vector<Region>& pool) appends the region's evaluated children to the pool.
template <class Region, class Split>
RefineOutcome refine(std::vector<Region>& pool, Split&& split, double tolerance, double floor, size_t max_splits) {
    // The heap holds (priority, index into pool) pairs: regions are large, the heap moves only pairs.
    thread_local std::vector<std::pair<double, size_t>> heap;
    heap.clear();
    auto prio = [](const Region& r) { return r.forced ? 1e300 : r.indicator; };
    RefineOutcome out;
    double total[3] = {0, 0, 0}, err = 0;
    for (size_t i = 0; i < pool.size(); ++i) {
        for (int c = 0; c < 3; ++c) total[c] += pool[i].fine[c];
        err += pool[i].indicator;
        if (pool[i].splittable) heap.emplace_back(prio(pool[i]), i);
    }
    std::make_heap(heap.begin(), heap.end());
    thread_local std::vector<char> gone; // split regions (replaced by their children)
    gone.assign(pool.size(), 0);
    while (!heap.empty()) {
        const auto [p, idx] = heap.front();
        if (p < 1e300 && err <= tolerance * (rgb_size(total) + floor)) break;
        if (out.splits >= max_splits) {
            out.budget_hit = true;
            break;
        }
        std::pop_heap(heap.begin(), heap.end());
        heap.pop_back();
        ++out.splits;
        const size_t first = pool.size();
        const Region r = pool[idx]; // copy: split() appends to the pool
        split(r, pool);
        gone[idx] = 1;
        gone.resize(pool.size(), 0);
        for (int c = 0; c < 3; ++c) total[c] -= r.fine[c];
        err -= r.indicator;
        for (size_t k = first; k < pool.size(); ++k) {
            for (int c = 0; c < 3; ++c) total[c] += pool[k].fine[c];
            err += pool[k].indicator;
            if (pool[k].splittable) {
                heap.emplace_back(prio(pool[k]), k);
                std::push_heap(heap.begin(), heap.end());
            }
        }
    }
    // Exact sums over the final regions (the running totals drift by rounding).
    for (size_t i = 0; i < pool.size(); ++i) {
        if (gone[i]) continue;
        for (int c = 0; c < 3; ++c) out.value[c] += pool[i].fine[c];
        out.error += pool[i].indicator;
        ++out.regions;
    }
    return out;
}

} // namespace iblcheck::truth
