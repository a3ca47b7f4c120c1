// Bit-identical images. bit_identical: the same bytes, NaN and Inf included (a golden is rewritten
// only when its bytes change; a repeated render must give the same bytes). identical_finite: a render
// equal to its baseline (the usual pass), for which every metric's result is known exactly, so FLIP,
// SSIM and PSNR skip their work (issue 33).
#pragma once
#include <opencv2/core.hpp>

#include <cmath>
#include <cstring>

namespace iblcheck {

// Same size, type and bytes, row by row (either may be a view into a larger image).
inline bool bit_identical(const cv::Mat& a, const cv::Mat& b) {
    if (a.size() != b.size() || a.type() != b.type()) return false;
    if (a.data == b.data && a.step[0] == b.step[0]) return true; // the same pixels
    const size_t row_bytes = size_t(a.cols) * a.elemSize();
    for (int y = 0; y < a.rows; ++y)
        if (std::memcmp(a.ptr(y), b.ptr(y), row_bytes) != 0) return false;
    return true;
}

// Bit-identical float images with no NaN or Inf (whose error is not 0).
inline bool identical_finite(const cv::Mat& a, const cv::Mat& b) {
    if (a.depth() != CV_32F || !bit_identical(a, b)) return false;
    const size_t n = size_t(a.cols) * a.channels();
    for (int y = 0; y < a.rows; ++y) {
        const float* p = a.ptr<float>(y);
        for (size_t i = 0; i < n; ++i)
            if (!std::isfinite(p[i])) return false;
    }
    return true;
}

} // namespace iblcheck
