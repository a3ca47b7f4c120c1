// One quadrature-truth golden and its sidecar (truth_golden.h).
#include "renderers/reference/truth_golden.h"

#include <ctime>
#include <filesystem>
#include <fstream>

#include "harness/common/errors.h"
#include "metrics/flip.h"
#include "metrics/image_io.h"

namespace iblcheck::truth {

std::string portable_env_spec(const std::string& spec) {
    if (spec.rfind("constant:", 0) == 0 || spec.rfind("blender:", 0) == 0 || spec == "studio" || spec == "sky_sun") return spec;
    return std::filesystem::path(spec).filename().string();
}

namespace {
std::string utc_now() {
    char date[64];
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    return date;
}

// Mean FLIP per sphere (over the pixels the sphere covers most of).
void add_sphere_flip(nlohmann::json& per_sphere, const cv::Mat& errmap, const cv::Mat& sphere) {
    std::vector<double> sum(per_sphere.size(), 0.0);
    std::vector<long> n(per_sphere.size(), 0);
    for (int y = 0; y < errmap.rows; ++y)
        for (int x = 0; x < errmap.cols; ++x) {
            const int s = sphere.at<int>(y, x);
            if (s < 0 || size_t(s) >= sum.size()) continue;
            sum[size_t(s)] += errmap.at<float>(y, x), ++n[size_t(s)];
        }
    for (size_t s = 0; s < sum.size(); ++s) per_sphere[s]["mean_flip"] = n[s] ? sum[s] / double(n[s]) : 0.0;
}
} // namespace

GoldenWritten write_truth_golden(const GoldenRequest& req) {
    const Environment env = load_environment(req.spec.env);
    TruthRender r = render_truth(req.spec, env, req.progress);
    const FlipResult flip = compute_flip_hdr(r.fine.image, r.coarse.image, FlipOptions{});
    GoldenWritten out;
    out.mean_flip = flip.mean;
    const double rel = r.bound.relative_rmse;
    out.criterion_met = flip.mean < kCriterionFlip && rel < kCriterionRelativeRmse;
    nlohmann::json bound = r.bound.json();
    add_sphere_flip(bound["per_sphere"], flip.errmap, r.fine.sphere);
    bound["mean_flip"] = flip.mean;
    bound["definition"] =
        "the golden is the finer of two refinement levels (every tolerance / 4, lobe guard / 2, one more sub-texel and "
        "footprint level); the bound is the difference between the two: relative_rmse = sqrt(mean((a-b)^2 / (m^2 + 0.01))), "
        "m = (a+b)/2, over covered pixels and channels; worst_pixel = the largest per-pixel term sqrt((a-b)^2/(m^2+0.01)); "
        "worst_pixel_relative = the largest |a-b|/m over pixels with m > 0.01; mean_flip = HDR-FLIP(finer, coarser)";
    bound["criterion"] = {{"mean_flip_below", kCriterionFlip},
                          {"relative_rmse_below", kCriterionRelativeRmse},
                          {"mean_flip_met", flip.mean < kCriterionFlip},
                          {"relative_rmse_met", rel < kCriterionRelativeRmse},
                          {"met", out.criterion_met}};
    nlohmann::json prov = r.result.provenance;
    prov.erase("error_bound");
    prov["env"]["spec"] = portable_env_spec(req.spec.env);
    const std::filesystem::path exr(req.out_exr);
    write_exr(req.out_exr, r.fine.image);
    out.meta = {{"scene", req.spec.scene},
                {"options", req.spec.options.canonical()},
                {"width", r.fine.image.cols},
                {"height", r.fine.image.rows},
                {"env", {{"spec", portable_env_spec(req.spec.env)},
                         {"content_hash", env.content_hash},
                         {"negatives_clamped", env.negatives_clamped}}},
                {"integrator", "quadrature"},
                {"deterministic", true},
                {"error_bound", bound},
                {"provenance", prov},
                {"time_s", prov["time_s"]},
                {"command", req.command},
                {"date", utc_now()},
                {"image", exr.filename().string()},
                {"channels", "R,G,B float32 linear"}};
    const std::string meta_path = std::filesystem::path(exr).replace_extension(".json").string();
    std::ofstream f(meta_path);
    f << out.meta.dump(2) << "\n";
    if (!f) throw InputError(meta_path + ": cannot write");
    return out;
}

} // namespace iblcheck::truth
