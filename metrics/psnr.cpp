#include "metrics/psnr.h"

#include <cmath>
#include <limits>

#include "kernel/errors.h"
#include "metrics/identical.h"

namespace iblcheck {

namespace {
void check(const cv::Mat& a, const cv::Mat& b, const char* what) {
    if (a.depth() != CV_32F || a.type() != b.type() || a.size() != b.size())
        throw InputError(std::string(what) + ": inputs must be float images of the same size and type");
}
} // namespace

PsnrResult compute_psnr(const cv::Mat& ref, const cv::Mat& test, double data_range, bool skip_identical) {
    check(ref, test, "PSNR");
    if (skip_identical && identical_finite(ref, test)) return {std::numeric_limits<double>::infinity(), 0.0, 0.0, 0.0};
    double sse = 0.0, max_abs = 0.0;
    const int n = ref.cols * ref.channels();
    for (int y = 0; y < ref.rows; ++y) {
        const float *r = ref.ptr<float>(y), *t = test.ptr<float>(y);
        for (int i = 0; i < n; ++i) {
            const double d = double(t[i]) - double(r[i]);
            sse += d * d;
            max_abs = std::max(max_abs, std::fabs(d));
        }
    }
    PsnrResult res;
    res.mse = sse / (double(ref.total()) * ref.channels());
    res.rmse = std::sqrt(res.mse);
    res.max_abs = max_abs;
    res.db = res.mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(data_range * data_range / res.mse);
    return res;
}

double compute_relative_mse(const cv::Mat& ref, const cv::Mat& test, double eps) {
    check(ref, test, "relative MSE");
    double sum = 0.0;
    const int n = ref.cols * ref.channels();
    for (int y = 0; y < ref.rows; ++y) {
        const float *r = ref.ptr<float>(y), *t = test.ptr<float>(y);
        for (int i = 0; i < n; ++i) {
            const double d = double(t[i]) - double(r[i]);
            sum += d * d / (double(r[i]) * double(r[i]) + eps);
        }
    }
    return sum / (double(ref.total()) * ref.channels());
}

} // namespace iblcheck
