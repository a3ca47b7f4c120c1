// The display transform of the linear scores: linear HDR radiance -> display sRGB in [0,1].
//   1. exposure 0 (radiance used as is),
//   2. Narkowicz's ACES fit ("ACES Filmic Tone Mapping Curve", 2016: a luminance-only fit of ACES's
//      RRT+ODT) with the 0.6 input scale he gives for the original ACES curve folded in: the same
//      curve and coefficients HDR-FLIP uses (metrics/flip/tone_mappers.h),
//   3. clamp to [0,1], then the sRGB OETF (IEC 61966-2-1).
// SSIM on HDR inputs and every PNG written for people go through this, so what a reviewer sees
// is what SSIM measured. It is the display space (display_space.h) aces_narkowicz, 0 EV, rgba32f,
// no quantisation (tests/test_display_space.cpp holds them equal); a suite's "display" scores
// tests in the space a player sees besides.
#pragma once
#include <opencv2/core.hpp>

#include "metrics/flip/color_spaces.h"
#include "metrics/flip/tone_mappers.h"

namespace iblcheck {

inline float display_transform_channel(float linear) {
    float v = flip::tone_map_channel(linear, flip::kToneCoefficients[int(flip::ToneMapper::aces)]);
    v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    return flip::linear_to_srgb(v);
}

// CV_32FC3 (or CV_32FC1) linear -> same type, display sRGB in [0,1].
inline cv::Mat display_transform(const cv::Mat& linear) {
    CV_Assert(linear.depth() == CV_32F);
    cv::Mat out(linear.size(), linear.type());
    const int n = linear.cols * linear.channels();
    for (int y = 0; y < linear.rows; ++y) {
        const float* s = linear.ptr<float>(y);
        float* d = out.ptr<float>(y);
        for (int i = 0; i < n; ++i) d[i] = display_transform_channel(s[i]);
    }
    return out;
}

} // namespace iblcheck
