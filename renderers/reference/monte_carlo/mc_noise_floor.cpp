// The Monte Carlo integrator's noise floor between two lighting seeds, and the relative RMSE it is
// measured with (monte_carlo.h: NoiseFloor, relative_rmse). Tests: mc_noise_floor_test.cpp.
#include <chrono>
#include <cmath>

#include "renderers/option_table.h"
#include "renderers/reference/monte_carlo/monte_carlo.h"

namespace iblcheck {

double relative_rmse(const cv::Mat& a, const cv::Mat& b, const cv::Mat& coverage, double* mean_value) {
    // Per-pixel relative error (relMSE, Rousselle et al. 2011): each squared difference is divided by
    // the squared local value, so a pixel that straddles the 1e5 sun's reflection weighs no more than
    // a dim one. The 1e-2 keeps black pixels from dividing by zero.
    double rel = 0, sum = 0;
    long n = 0;
    for (int y = 0; y < a.rows; ++y)
        for (int x = 0; x < a.cols; ++x) {
            if (coverage.at<float>(y, x) <= 0) continue;
            const auto& pa = a.at<cv::Vec3f>(y, x);
            const auto& pb = b.at<cv::Vec3f>(y, x);
            for (int c = 0; c < 3; ++c) {
                double d = double(pa[c]) - pb[c], m = 0.5 * (double(pa[c]) + pb[c]);
                rel += d * d / (m * m + 1e-2);
                sum += m;
            }
            ++n;
        }
    if (n == 0) return 0;
    if (mean_value) *mean_value = sum / (3.0 * n);
    return std::sqrt(rel / (3.0 * n));
}

NoiseFloor measure_noise_floor(const TestSpec& spec_in, int spp) {
    auto t0 = std::chrono::steady_clock::now();
    TestSpec spec = spec_in;
    NoiseFloor nf;
    nf.spp = spp;
    nf.seed_a = option_int(spec.options, "seed", "reference");
    nf.seed_b = nf.seed_a + 1;
    Environment env = load_environment(spec.env);
    spec.options.set("spp", std::to_string(spp));
    spec.options.set("seed", std::to_string(nf.seed_a));
    ReferenceRender a = render_reference_full(spec, &env);
    spec.options.set("seed", std::to_string(nf.seed_b));
    ReferenceRender b = render_reference_full(spec, &env);
    nf.relative_rmse = relative_rmse(a.result.image, b.result.image, a.coverage, &nf.mean_value);
    nf.covered_pixels = cv::countNonZero(a.coverage > 0);
    nf.image_a = a.result.image;
    nf.image_b = b.result.image;
    nf.provenance_a = a.result.provenance;
    nf.coverage = a.coverage;
    nf.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return nf;
}

} // namespace iblcheck
