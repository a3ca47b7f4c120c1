#include "metrics/ssim.h"

#include <opencv2/imgproc.hpp>

#include "kernel/errors.h"
#include "metrics/display_transform.h"
#include "metrics/identical.h"

namespace iblcheck {

namespace {
constexpr double kK1 = 0.01, kK2 = 0.03, kL = 1.0, kSigma = 1.5;
constexpr int kRadius = 5; // int(3.5 * sigma + 0.5), scikit-image's truncation

cv::Mat blur(const cv::Mat& m, const cv::Mat& k) {
    cv::Mat out;
    cv::sepFilter2D(m, out, CV_64F, k, k, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
    return out;
}
} // namespace

SsimResult compute_ssim(const cv::Mat& a, const cv::Mat& b, bool skip_identical) {
    if (a.type() != CV_32FC3 || b.type() != CV_32FC3 || a.size() != b.size())
        throw InputError("SSIM: inputs must be CV_32FC3 of the same size");
    if (a.cols < 2 * kRadius + 1 || a.rows < 2 * kRadius + 1) throw InputError("SSIM: images must be at least 11x11");
    if (skip_identical && identical_finite(a, b)) return {1.0, {1.0, 1.0, 1.0}};
    // Normalised Gaussian taps (what scipy.ndimage.gaussian_filter uses).
    cv::Mat k = cv::getGaussianKernel(2 * kRadius + 1, kSigma, CV_64F);
    const double c1 = (kK1 * kL) * (kK1 * kL), c2 = (kK2 * kL) * (kK2 * kL);
    std::vector<cv::Mat> ca, cb;
    cv::split(a, ca);
    cv::split(b, cb);
    SsimResult r;
    const cv::Rect valid(kRadius, kRadius, a.cols - 2 * kRadius, a.rows - 2 * kRadius);
    for (int c = 0; c < 3; ++c) {
        cv::Mat x, y;
        ca[c].convertTo(x, CV_64F);
        cb[c].convertTo(y, CV_64F);
        const cv::Mat ux = blur(x, k), uy = blur(y, k);
        const cv::Mat uxx = blur(x.mul(x), k), uyy = blur(y.mul(y), k), uxy = blur(x.mul(y), k);
        double sum = 0.0;
        for (int j = valid.y; j < valid.y + valid.height; ++j) {
            const double *px = ux.ptr<double>(j), *py = uy.ptr<double>(j);
            const double *pxx = uxx.ptr<double>(j), *pyy = uyy.ptr<double>(j), *pxy = uxy.ptr<double>(j);
            for (int i = valid.x; i < valid.x + valid.width; ++i) {
                const double mx = px[i], my = py[i];
                const double vx = pxx[i] - mx * mx, vy = pyy[i] - my * my, vxy = pxy[i] - mx * my;
                // Eq. 13 of Wang et al. 2004.
                sum += ((2 * mx * my + c1) * (2 * vxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            }
        }
        r.per_channel[c] = sum / double(valid.area());
    }
    r.mean = (r.per_channel[0] + r.per_channel[1] + r.per_channel[2]) / 3.0;
    return r;
}

SsimResult compute_ssim_hdr(const cv::Mat& ref_linear, const cv::Mat& test_linear) {
    return compute_ssim(display_transform(ref_linear), display_transform(test_linear));
}

} // namespace iblcheck
