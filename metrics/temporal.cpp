#include "metrics/temporal.h"

#include <cmath>
#include <limits>
#include <string>

#include "kernel/errors.h"

namespace iblcheck {

TemporalResult compute_temporal(const std::vector<cv::Mat>& test, const std::vector<cv::Mat>& ref) {
    if (test.size() != ref.size())
        throw InputError("temporal: " + std::to_string(test.size()) + " test frames but " + std::to_string(ref.size()) +
                         " reference frames");
    if (test.size() < 2) throw InputError("temporal: at least 2 frames are needed");
    for (size_t t = 0; t < test.size(); ++t) {
        if (test[t].depth() != CV_32F || test[t].type() != ref[t].type() || test[t].size() != ref[t].size() ||
            test[t].size() != test[0].size() || test[t].type() != test[0].type())
            throw InputError("temporal: frame " + std::to_string(t) +
                             " differs in size or type from the others (float frames needed)");
    }
    double flicker = 0.0, var_t = 0.0, var_r = 0.0;
    size_t count = 0;
    const int n = test[0].cols * test[0].channels();
    for (size_t t = 1; t < test.size(); ++t) {
        for (int y = 0; y < test[t].rows; ++y) {
            const float *t1 = test[t].ptr<float>(y), *t0 = test[t - 1].ptr<float>(y);
            const float *r1 = ref[t].ptr<float>(y), *r0 = ref[t - 1].ptr<float>(y);
            for (int i = 0; i < n; ++i) {
                const double dt = double(t1[i]) - double(t0[i]);
                const double dr = double(r1[i]) - double(r0[i]);
                flicker += std::fabs(dt - dr);
                var_t += std::fabs(dt);
                var_r += std::fabs(dr);
                ++count;
            }
        }
    }
    TemporalResult r;
    r.frames = int(test.size());
    r.flicker = flicker / double(count);
    if (var_r > 0.0)
        r.variation_ratio = var_t / var_r;
    else
        r.variation_ratio = var_t > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
    return r;
}

} // namespace iblcheck
