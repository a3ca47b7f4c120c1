// Spatial (contrast sensitivity) filters of FLIP (FLIP paper, Sec. 4.1, Eqs. 2-3).
// The CSF of each opponent channel is a sum of Gaussians in the frequency domain; its spatial
// counterpart is again a sum of Gaussians, a * sqrt(pi / b) * exp(-pi^2 x^2 / b) (Eq. 3).
// Y and Cx use one Gaussian each, so their 2D filters are separable outright. Cz uses two, and
// g1(x)g1(y) + g2(x)g2(y) is split into two separable filters whose 1D taps are the square roots
// of the amplitudes ("GaussianSqrt"), filtered separately and summed after the vertical pass
// (NVlabs/flip, misc/separatedConvolutions.pdf).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "metrics/flip/flip_constants.h"

namespace iblcheck::flip {

// Eq. 3 with x^2 given: a * sqrt(pi / b) * exp(-pi^2 x^2 / b).
inline float csf_gaussian(float x2, float a, float b) {
    const float pi = kPi;
    const float pi_sq = kPi * kPi;
    return a * std::sqrt(pi / b) * std::exp(-pi_sq * x2 / b);
}
// The same with sqrt of the amplitude: one factor of a separable product of two 1D filters.
inline float csf_gaussian_sqrt(float x2, float a, float b) {
    const float pi = kPi;
    const float pi_sq = kPi * kPi;
    return std::sqrt(a * std::sqrt(pi / b)) * std::exp(-pi_sq * x2 / b);
}

// Radius covering 3 standard deviations of the widest spatial Gaussian: the Gaussian of Eq. 3
// has std dev sqrt(b / (2 pi^2)) degrees.
inline int spatial_filter_radius(float ppd) {
    const float pi_sq = kPi * kPi;
    const float max_b = std::max({kCsfY.b1, kCsfCx.b1, kCsfCz.b1, kCsfY.b2, kCsfCx.b2, kCsfCz.b2});
    return int(std::ceil(3.0f * std::sqrt(max_b / (2.0f * pi_sq)) * ppd));
}

// 1D taps (2 * radius + 1 of them) of the four separable spatial filters.
struct SpatialFilters {
    int radius = 0;
    std::vector<float> y, cx, cz1, cz2;
};

inline SpatialFilters make_spatial_filters(float ppd) {
    SpatialFilters f;
    f.radius = spatial_filter_radius(ppd);
    const int width = 2 * f.radius + 1;
    const float dx = 1.0f / ppd; // pixel pitch in degrees
    f.y.resize(width);
    f.cx.resize(width);
    f.cz1.resize(width);
    f.cz2.resize(width);
    float sum_y = 0.0f, sum_cx = 0.0f, sum_cz1 = 0.0f, sum_cz2 = 0.0f;
    for (int i = 0; i < width; ++i) {
        const float x = float(i - f.radius) * dx;
        const float x2 = x * x;
        f.y[i] = csf_gaussian(x2, kCsfY.a1, kCsfY.b1);
        f.cx[i] = csf_gaussian(x2, kCsfCx.a1, kCsfCx.b1);
        f.cz1[i] = csf_gaussian_sqrt(x2, kCsfCz.a1, kCsfCz.b1);
        f.cz2[i] = csf_gaussian_sqrt(x2, kCsfCz.a2, kCsfCz.b2);
        sum_y += f.y[i];
        sum_cx += f.cx[i];
        sum_cz1 += f.cz1[i];
        sum_cz2 += f.cz2[i];
    }
    // Each 2D filter sums to one: Y and Cx per axis; for Cz the 2D sum is s1^2 + s2^2, so both
    // 1D parts are divided by its square root.
    const float norm_y = 1.0f / sum_y, norm_cx = 1.0f / sum_cx;
    const float norm_cz = 1.0f / std::sqrt(sum_cz1 * sum_cz1 + sum_cz2 * sum_cz2);
    for (int i = 0; i < width; ++i) {
        f.y[i] *= norm_y;
        f.cx[i] *= norm_cx;
        f.cz1[i] *= norm_cz;
        f.cz2[i] *= norm_cz;
    }
    return f;
}

} // namespace iblcheck::flip
