// The adaptive lighting-sample counts (mc_adaptive.h).
#include "renderers/reference/monte_carlo/mc_adaptive.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace iblcheck::reference {

std::vector<int> adaptive_counts(const std::vector<double>& r, const std::vector<char>& partial, int W, int H,
                                 const AdaptiveLimits& limits) {
    const int m_mean = limits.mean;
    std::vector<int> counts(size_t(W) * H, m_mean);
    // The 3x3 maximum of r, and its mean over the pixels where it is positive.
    std::vector<double> rm(r.size(), -1.0);
    double sum = 0;
    long cnt = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (r[size_t(y) * W + x] < 0) continue;
            double m = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int yy = y + dy, xx = x + dx;
                    if (yy >= 0 && yy < H && xx >= 0 && xx < W) m = std::max(m, r[size_t(yy) * W + xx]);
                }
            rm[size_t(y) * W + x] = m;
            if (m > 0) sum += m, ++cnt;
        }
    double mean_r = cnt ? sum / cnt : 0;
    for (size_t i = 0; i < rm.size(); ++i) {
        if (rm[i] < 0) continue; // no sphere can be hit: the count is irrelevant
        double c = mean_r > 0 ? m_mean * rm[i] / mean_r : m_mean;
        counts[i] = int(std::clamp(std::lround(c), long(std::max(1, m_mean / 4)), long(limits.cap) * m_mean));
        if (partial[i]) counts[i] = std::max(counts[i], limits.silhouette_boost * m_mean);
    }
    return counts;
}

} // namespace iblcheck::reference
