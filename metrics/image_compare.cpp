#include "metrics/image_compare.h"

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
json ssim_json(const cv::Mat& g, const cv::Mat& t) {
    return ssim_applicable(g) ? json{{"mean", compute_ssim(g, t).mean}} : ssim_not_applicable();
}
json psnr_json(const PsnrResult& p) {
    return {{"db", std::isfinite(p.db) ? json(p.db) : json(kPsnrIdentical)}, {"rmse", p.rmse}, {"max_abs", p.max_abs}};
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
              {"display_ssim", ssim_json(g, t)},
              {"display_psnr", psnr_json(compute_psnr(g, t))}};
    if (flip_out) *flip_out = std::move(f);
    return j;
}

json compare_images(const cv::Mat& golden, const cv::Mat& test, const CompareOptions& o, FlipResult* flip_out) {
    json j = json::object();
    if (o.want_flip) {
        FlipResult f = o.hdr ? compute_flip_hdr(golden, test, o.flip_options) : compute_flip_ldr(golden, test, o.flip_options);
        j["flip"] = flip_json(f);
        if (flip_out) *flip_out = std::move(f);
    }
    if (o.want_ssim || o.want_psnr) {
        // SSIM and PSNR on the display values, computed once for both (compute_ssim_hdr's); a
        // render bit-identical to its golden transforms once, and both metrics skip
        // (metrics/identical.h).
        const bool same = identical_finite(golden, test);
        const cv::Mat dg = o.hdr ? display_transform(golden) : golden;
        const cv::Mat dt = !o.hdr ? test : same ? dg : display_transform(test);
        if (o.want_psnr) j["psnr"] = psnr_json(compute_psnr(dg, dt));
        if (o.want_ssim) j["ssim"] = ssim_json(dg, dt);
    }
    if (o.hdr && o.want_psnr && o.linear_psnr) {
        j["linear_psnr"] = psnr_json(compute_psnr(golden, test));
        j["linear_psnr"]["relative_mse"] = compute_relative_mse(golden, test);
    }
    if (o.display) j.update(compare_in_display(golden, test, *o.display, o.flip_options.threads));
    return j;
}

json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out,
                    const DisplaySpace* display) {
    CompareOptions o;
    o.flip_options.threads = flip_threads;
    o.display = display;
    return compare_images(golden, test, o, flip_out);
}

json measure_against_golden(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace* display, int flip_threads,
                            FlipResult& linear, FlipResult& shown) {
    json m = compare_images(golden, test, flip_threads, &linear);
    if (!display) {
        shown = linear;
        return m;
    }
    m.update(compare_in_display(golden, test, *display, flip_threads, &shown));
    return m;
}

} // namespace iblcheck
