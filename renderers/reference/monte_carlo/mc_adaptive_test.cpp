// The adaptive lighting-sample counts (mc_adaptive.h) against their contract.
#include "renderers/reference/monte_carlo/mc_adaptive.h"

#include <gtest/gtest.h>

#include <vector>

using namespace iblcheck::reference;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace mc_adaptive_test {

// 5x1 pixels: counts ∝ the 3x3 maximum of r relative to its mean, clamped to [M̄/4, cap·M̄]; pixels
// nothing can hit (r < 0) keep M̄; silhouette pixels get at least boost·M̄.
TEST(McAdaptive, CountsFollowTheNeighbourhoodMaximumWithinTheLimits) {
    const std::vector<double> r = {-1, 1, 1, 1, 4};
    const std::vector<char> silhouette = {0, 0, 0, 0, 0};
    const AdaptiveLimits lim{8, 16, 16};
    const std::vector<int> c = adaptive_counts(r, silhouette, 5, 1, lim);
    // 3x3 maxima: -, 1, 1, 4, 4; mean 2.5 -> 8·m/2.5
    EXPECT_EQ(c, (std::vector<int>{8, 3, 3, 13, 13}));
    // The clamp: a tiny ratio gets M̄/4, a huge one cap·M̄.
    const std::vector<int> d = adaptive_counts({1e-6, 1e-6, -1, -1, 1e3}, silhouette, 5, 1, AdaptiveLimits{8, 2, 16});
    EXPECT_EQ(d[0], 2);
    EXPECT_EQ(d[4], 16);
    // Silhouette pixels: at least boost·M̄.
    const std::vector<int> e = adaptive_counts(r, {0, 1, 0, 0, 0}, 5, 1, AdaptiveLimits{8, 16, 4});
    EXPECT_EQ(e[1], 32);
    EXPECT_EQ(e[2], 3);
}

TEST(McAdaptive, UniformNoiseGivesTheMeanCount) {
    const int W = 7, H = 5;
    const std::vector<int> c = adaptive_counts(std::vector<double>(size_t(W) * H, 0.3), std::vector<char>(size_t(W) * H, 0), W, H,
                                               AdaptiveLimits{4, 16, 16});
    for (int v : c) EXPECT_EQ(v, 4);
    // No noise anywhere (r = 0): every count is M̄.
    const std::vector<int> z = adaptive_counts(std::vector<double>(size_t(W) * H, 0.0), std::vector<char>(size_t(W) * H, 0), W, H,
                                               AdaptiveLimits{4, 16, 16});
    for (int v : z) EXPECT_EQ(v, 4);
}
} // namespace mc_adaptive_test
