// Pooling of a FLIP error map into the numbers the reference tool reports (Andersson et al.
// 2021, "Visualizing and Communicating Errors in Rendered Images", Ray Tracing Gems II, ch. 19):
// mean, min, max, and the weighted median and quartiles, where each pixel counts with its own
// error value, so large errors dominate the statistic.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace iblcheck::flip {

// The tool's printed "weighted median" / quartiles: with the error values sorted ascending and
// summed in float, the first value at which the running sum exceeds fraction * total, where total
// is the float sum in row order. `sorted` must be ascending; `total_float` the row-order sum.
inline float weighted_percentile_sorted(const std::vector<float>& sorted, float total_float,
                                        float fraction) {
    float running = 0.0f;
    const float target = fraction * total_float;
    for (float v : sorted) {
        running += v;
        if (running > target) return v;
    }
    return 0.0f;
}

// Ascending sort of non-negative floats by their bit patterns (monotonic for v >= 0): LSD radix
// sort, 3 passes of 11 bits. ~10x faster than std::sort on a 1080p error map.
inline void radix_sort_nonnegative(std::vector<float>& v) {
    const size_t n = v.size();
    std::vector<uint32_t> a(n), b(n);
    std::memcpy(a.data(), v.data(), n * sizeof(float));
    for (int pass = 0; pass < 3; ++pass) {
        const int shift = pass * 11;
        std::array<size_t, 2048> count{};
        for (uint32_t k : a) ++count[(k >> shift) & 2047u];
        size_t sum = 0;
        for (auto& c : count) {
            const size_t t = c;
            c = sum;
            sum += t;
        }
        for (uint32_t k : a) b[count[(k >> shift) & 2047u]++] = k;
        a.swap(b);
    }
    std::memcpy(v.data(), a.data(), n * sizeof(float));
}

// The tool's 100-bucket histogram (what its weighted-histogram plot shows; kept for reports) over [0,1]: bucket = size_t(double(v) / 0.01f), v == 1 goes to
// the last bucket, values outside [0,1] are not counted.
struct WeightedHistogram {
    static constexpr size_t kBuckets = 100;
    std::vector<size_t> counts = std::vector<size_t>(kBuckets, 0);

    void add(float v) {
        const float bucket_size = 1.0f / float(kBuckets);
        if (v < 0.0f || v > 1.0f) return;
        size_t id = size_t(double(v) / bucket_size);
        if (id == kBuckets) --id;
        ++counts[id];
    }
    void merge(const WeightedHistogram& o) {
        for (size_t i = 0; i < kBuckets; ++i) counts[i] += o.counts[i];
    }

    // Percentile of the error-weighted distribution: bucket i has weight count * (i + 0.5) * step;
    // find the bucket where the running weight crosses `fraction` of the total and interpolate
    // linearly inside it.
    double weighted_percentile(double fraction) const {
        const double step = double(1.0f / float(kBuckets));
        double total = 0.0;
        for (size_t i = 0; i < kBuckets; ++i) total += double(counts[i]) * ((double(i) + 0.5) * step);
        double sum = 0.0;
        size_t idx = 0;
        for (size_t i = 0; i < kBuckets; ++i) {
            const double w = double(counts[i]) * ((double(i) + 0.5) * step);
            idx = i;
            if (sum + w > fraction * total) break;
            sum += w;
        }
        const double w = double(counts[idx]) * ((double(idx) + 0.5) * step);
        if (w == 0.0) return double(idx) * step; // all-zero error map
        return (double(idx) + (fraction * total - sum) / w) * step;
    }
};

} // namespace iblcheck::flip
