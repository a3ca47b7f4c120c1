// Pixel-wise error statistics. All in double over every channel value of CV_32FC3 inputs.
#pragma once
#include <opencv2/core.hpp>

namespace iblcheck {

struct PsnrResult {
    double db = 0; // 10 log10(range^2 / MSE); +inf for identical images
    double mse = 0;
    double rmse = 0;
    double max_abs = 0; // largest |test - ref| over all channel values
};

// PSNR with data range 1 (display values in [0,1]), as scikit-image's
// peak_signal_noise_ratio(data_range=1).
// skip_identical: bit-identical finite inputs (metrics/identical.h) give what the loop computes for
// them without it: every difference +0.0, so MSE, RMSE and max_abs 0 and db +inf.
PsnrResult compute_psnr(const cv::Mat& ref, const cv::Mat& test, double data_range = 1.0, bool skip_identical = true);

// Relative MSE for HDR radiance: mean over channel values of (t - r)^2 / (r^2 + eps), eps = 1e-2.
// Dividing by r^2 makes an error count relative to the local brightness (a 0.1 error on a
// radiance of 100 is small, on 0.1 it is not); eps keeps black pixels finite. (Rousselle et al.
// 2011's relMSE, with eps = 0.01 as used in denoising literature.)
double compute_relative_mse(const cv::Mat& ref_linear, const cv::Mat& test_linear, double eps = 1e-2);

} // namespace iblcheck
