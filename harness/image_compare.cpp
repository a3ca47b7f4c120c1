#include "image_compare.h"

#include <cmath>

#include "metrics/display_transform.h"
#include "metrics/flip_json.h"
#include "metrics/identical.h"
#include "metrics/psnr.h"
#include "metrics/ssim.h"

using nlohmann::json;

namespace iblcheck {

namespace {
json ssim_not_applicable() { return {{"mean", nullptr}, {"not_applicable", "smaller than SSIM's 11x11 window"}}; }
// Identical images have PSNR +inf, which JSON cannot hold: 999 stands for it.
json psnr_json(const PsnrResult& p) {
    return {{"db", std::isfinite(p.db) ? json(p.db) : json(999.0)}, {"rmse", p.rmse}, {"max_abs", p.max_abs}};
}
} // namespace

json compare_in_display(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace& display, int flip_threads,
                        FlipResult* flip_out) {
    // A render bit-identical to its golden shows the same display image: transformed once.
    const cv::Mat g = to_display(golden, display), t = identical_finite(golden, test) ? g : to_display(test, display);
    FlipOptions fo;
    fo.threads = flip_threads;
    FlipResult f = compute_flip_ldr(g, t, fo);
    json j = {{"display", display_json(display)},
              {"display_flip", flip_json(f)},
              {"display_ssim", ssim_applicable(g) ? json{{"mean", compute_ssim(g, t).mean}} : ssim_not_applicable()},
              {"display_psnr", psnr_json(compute_psnr(g, t))}};
    if (flip_out) *flip_out = std::move(f);
    return j;
}

json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out,
                    const DisplaySpace* display) {
    FlipOptions fo;
    fo.threads = flip_threads;
    FlipResult f = compute_flip_hdr(golden, test, fo);
    // SSIM and PSNR on the display transform, computed once for both (compute_ssim_hdr's); a render
    // bit-identical to its golden transforms once, and both metrics skip (metrics/identical.h).
    const cv::Mat dg = display_transform(golden), dt = identical_finite(golden, test) ? dg : display_transform(test);
    PsnrResult p = compute_psnr(dg, dt);
    json j;
    j["flip"] = flip_json(f);
    j["ssim"] = ssim_applicable(golden) ? json{{"mean", compute_ssim(dg, dt).mean}} : ssim_not_applicable();
    j["psnr"] = psnr_json(p);
    if (display) j.update(compare_in_display(golden, test, *display, flip_threads));
    if (flip_out) *flip_out = std::move(f);
    return j;
}

json per_sphere_errors(const SphereCoverage& coverage, const cv::Mat& errmap) {
    const size_t n = coverage.spheres.size();
    if (n < 2) return json();
    std::vector<double> sum(n, 0.0);
    std::vector<long> count(n, 0);
    for (int y = 0; y < errmap.rows; ++y)
        for (int x = 0; x < errmap.cols; ++x) {
            int id = coverage.ids.at<int>(y, x);
            if (id < 0) continue;
            sum[size_t(id)] += errmap.at<float>(y, x);
            count[size_t(id)]++;
        }
    json out = json::array();
    for (size_t i = 0; i < n; ++i) {
        if (!count[i]) continue;
        const SphereCoverage::Sphere& s = coverage.spheres[i];
        out.push_back(
            {{"label", s.label}, {"roughness", s.roughness}, {"metallic", s.metallic}, {"flip_mean", sum[i] / double(count[i])}});
    }
    return out;
}

SphereLayout sphere_layout(const SphereCoverage& coverage) {
    SphereLayout out;
    if (coverage.spheres.size() > 254) return out; // does not fit the 8-bit map: no layout
    coverage.ids.convertTo(out.ids, CV_8U, 1.0, 1.0);
    for (const SphereCoverage::Sphere& s : coverage.spheres)
        out.spheres.push_back({{"label", s.label}, {"roughness", s.roughness}, {"metallic", s.metallic}});
    return out;
}

std::string sphere_at(const SphereCoverage& coverage, int x, int y) {
    int id = coverage.ids.at<int>(y, x);
    return id < 0 ? "" : coverage.spheres[size_t(id)].label;
}

} // namespace iblcheck
