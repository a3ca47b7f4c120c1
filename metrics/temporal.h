// Temporal stability of a tone-mapped frame sequence against a reference sequence (issue 3).
// With T_t the test frames and R_t the reference frames (same size, float):
//   flicker         = mean over t >= 1 and all pixel channels of |(T_t - T_{t-1}) - (R_t - R_{t-1})|
//                     (frame-to-frame change the reference does not have; 0 when the test moves
//                     exactly like the reference, e.g. a constant bias),
//   variation_ratio = sum |T_t - T_{t-1}| / sum |R_t - R_{t-1}| (1: as much change as the
//                     reference; > 1: extra shimmer; +inf when the reference is static and the test
//                     is not, 1 when both are static).
#pragma once
#include <vector>

#include <opencv2/core.hpp>

namespace iblcheck {

struct TemporalResult {
    double flicker = 0;
    double variation_ratio = 1;
    int frames = 0;
};

// Throws InputError when the sequences differ in length or frame size, or have < 2 frames.
TemporalResult compute_temporal(const std::vector<cv::Mat>& test, const std::vector<cv::Mat>& ref);

} // namespace iblcheck
