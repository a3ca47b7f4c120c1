// A deterministic synthetic sRGB image for metric and compare tests: smooth structure in [0,1]
// plus uniform noise of the given amplitude, the same for a given seed.
#pragma once
#include <algorithm>
#include <cmath>
#include <random>

#include <opencv2/core.hpp>

namespace iblcheck::testing_support {

inline cv::Mat synthetic(int w, int h, unsigned seed, float noise) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-noise, noise);
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            auto* p = m.ptr<float>(y) + 3 * x;
            p[0] = std::clamp(0.5f + 0.4f * std::sin(x * 0.1f) + u(rng), 0.0f, 1.0f);
            p[1] = std::clamp(0.5f + 0.4f * std::cos(y * 0.07f) + u(rng), 0.0f, 1.0f);
            p[2] = std::clamp(float(x + y) / float(w + h) + u(rng), 0.0f, 1.0f);
        }
    return m;
}

} // namespace iblcheck::testing_support
