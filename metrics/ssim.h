// SSIM (Wang, Bovik, Sheikh & Simoncelli 2004, "Image Quality Assessment: From Error Visibility
// to Structural Similarity", IEEE TIP 13(4)), configured like the paper and like scikit-image's
// structural_similarity(gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
// data_range=1): 11x11 Gaussian window (sigma 1.5, truncated at 3.5 sigma), K1 = 0.01,
// K2 = 0.03, L = 1, population (co)variances, SSIM map averaged over the valid region (a 5-pixel
// border is excluded, so the border handling of the filter never matters), computed per RGB
// channel and averaged. Arithmetic in double.
#pragma once
#include <opencv2/core.hpp>

namespace iblcheck {

// The Gaussian window's size: smaller images have no SSIM (the metric is not applicable).
inline constexpr int kSsimMinSize = 11;
inline bool ssim_applicable(const cv::Mat& m) { return m.cols >= kSsimMinSize && m.rows >= kSsimMinSize; }

struct SsimResult {
    double mean = 0; // mean over channels of the per-channel mean SSIM
    double per_channel[3] = {0, 0, 0};
};

// Inputs: CV_32FC3 display values in [0,1] (sRGB-encoded for LDR). Same size, >= 11x11.
// skip_identical: bit-identical finite inputs (metrics/identical.h) give 1 in every channel without
// the filtering, exactly what it computes: with x = y each window's numerator and denominator are
// the same products of the same doubles (2·mx·my = mx² + my², vxy = vx = vy), so each term is 1.0,
// their sum the count, and the means 1.0.
SsimResult compute_ssim(const cv::Mat& a, const cv::Mat& b, bool skip_identical = true);

// For HDR inputs: both go through display_transform() (metrics/display_transform.h) first.
SsimResult compute_ssim_hdr(const cv::Mat& ref_linear, const cv::Mat& test_linear);

} // namespace iblcheck
