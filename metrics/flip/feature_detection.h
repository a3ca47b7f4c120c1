// Edge and point detection filters of FLIP (FLIP paper, Sec. 4.2, Eq. 8): first and second
// derivatives of a Gaussian with std dev 0.5 * w * ppd pixels (w = 0.082 degrees), applied to
// the achromatic channel normalised to [0,1]. The 2D filters are separable: d/dx G(x,y) =
// G'(x) G(y), so one horizontal pass produces (G' * I, G'' * I, G * I) and the vertical pass
// combines them (NVlabs/flip, misc/separatedConvolutions.pdf).
#pragma once
#include <cmath>
#include <vector>

#include "metrics/flip/flip_constants.h"

namespace iblcheck::flip {

inline float feature_std_dev(float ppd) { return 0.5f * kW * ppd; }
inline int feature_filter_radius(float ppd) { return int(std::ceil(3.0f * feature_std_dev(ppd))); }

struct FeatureFilters {
    int radius = 0;
    std::vector<float> g, dg, ddg; // Gaussian, 1st and 2nd derivative taps
};

inline FeatureFilters make_feature_filters(float ppd) {
    FeatureFilters f;
    const float sd = feature_std_dev(ppd);
    f.radius = feature_filter_radius(ppd);
    const int width = 2 * f.radius + 1;
    f.g.resize(width);
    f.dg.resize(width);
    f.ddg.resize(width);
    float g_sum = 0.0f, dg_pos = 0.0f, dg_neg = 0.0f, ddg_pos = 0.0f, ddg_neg = 0.0f;
    for (int i = 0; i < width; ++i) {
        const float x = float(i - f.radius);
        const float g = std::exp(-(x * x) / (2.0f * sd * sd));
        g_sum += g;
        const float dg = -x * g;
        if (dg > 0.0f)
            dg_pos += dg;
        else
            dg_neg -= dg;
        const float ddg = (x * x / (sd * sd) - 1.0f) * g;
        if (ddg > 0.0f)
            ddg_pos += ddg;
        else
            ddg_neg -= ddg;
        f.g[i] = g;
        f.dg[i] = dg;
        f.ddg[i] = ddg;
    }
    // Gaussian taps sum to 1; the positive and negative lobes of each derivative sum to +1 and -1
    // so a step or a dot of full contrast gives a response of magnitude ~1 (FLIP paper, Sec. 4.2).
    for (int i = 0; i < width; ++i) {
        f.g[i] /= g_sum;
        f.dg[i] /= (f.dg[i] > 0.0f ? dg_pos : dg_neg);
        f.ddg[i] /= (f.ddg[i] > 0.0f ? ddg_pos : ddg_neg);
    }
    return f;
}

} // namespace iblcheck::flip
