// One quadrature-truth golden and its sidecar (truth_golden.h).
#include "harness/truth/truth_golden.h"

#include <filesystem>

#include "harness/golden_store.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/display_transform.h"
#include "metrics/flip.h"
#include "renderers/reference/monte_carlo/monte_carlo.h"

namespace iblcheck::truth {

std::string portable_env_spec(const TestSpec& spec) { return environment_label(spec.env, spec.env_name); }

GoldenDifference golden_difference(const std::string& new_exr, const std::string& old_exr) {
    const cv::Mat a = read_image(new_exr).pixels, o = read_image(old_exr).pixels;
    check_same_size(a, o, new_exr, old_exr);
    cv::Mat cov(a.rows, a.cols, CV_32FC1, cv::Scalar(0)); // covered: the background is exactly 0
    for (int y = 0; y < a.rows; ++y)
        for (int x = 0; x < a.cols; ++x) {
            const cv::Vec3f& p = a.at<cv::Vec3f>(y, x);
            if (p[0] > 0 || p[1] > 0 || p[2] > 0) cov.at<float>(y, x) = 1;
        }
    return {compute_flip_hdr(o, a, FlipOptions{}).mean, relative_rmse(a, o, cov)};
}

namespace {

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
        "the golden is the finer of two refinement levels (every tolerance / 2, lobe guard / sqrt(2), the footprint's "
        "variation bound one level deeper: provenance.levels); the bound is the difference between the two: relative_rmse = "
        "sqrt(mean((a-b)^2 / (m^2 + 0.01))), "
        "m = (a+b)/2, over covered pixels and channels; worst_pixel = the largest per-pixel term sqrt((a-b)^2/(m^2+0.01)); "
        "worst_pixel_relative = the largest |a-b|/m over pixels with m > 0.01; mean_flip = HDR-FLIP(finer, coarser). Not in it: "
        "an error that does not shrink between the "
        "levels, measured at up to 6e-4 of a silhouette pixel's value (renderers/reference/CONVERGENCE.md)";
    bound["criterion"] = {{"mean_flip_below", kCriterionFlip},
                          {"relative_rmse_below", kCriterionRelativeRmse},
                          {"mean_flip_met", flip.mean < kCriterionFlip},
                          {"relative_rmse_met", rel < kCriterionRelativeRmse},
                          {"met", out.criterion_met}};
    nlohmann::json prov = r.result.provenance;
    prov.erase("error_bound");
    prov["env"]["spec"] = portable_env_spec(req.spec);
    const std::filesystem::path exr(req.out_exr);
    out.meta = {{"scene", req.spec.scene},
                {"options", req.spec.options.canonical()},
                {"width", r.fine.image.cols},
                {"height", r.fine.image.rows},
                {"env",
                 {{"spec", portable_env_spec(req.spec)},
                  {"content_hash", env.content_hash},
                  {"negatives_clamped", env.negatives_clamped}}},
                {"integrator", "quadrature"},
                {"deterministic", true},
                {"error_bound", bound},
                {"provenance", prov},
                {"time_s", prov["time_s"]},
                {"command", req.command},
                {"date", utc_now_iso()},
                {"image", exr.filename().string()},
                {"channels", "R,G,B float32 linear"}};
    GoldenStore::write_golden(req.out_exr, r.fine.image, out.meta);
    return out;
}

nlohmann::json sequence_criterion(double worst_ldr, double worst_flip, double worst_rel) {
    const bool ldr = worst_ldr < kSequenceCriterionLdrFlip, hdr = worst_flip < kSequenceCriterionFlip,
               rel = worst_rel < kSequenceCriterionRelativeRmse;
    return {{"mean_flip_ldr_below", kSequenceCriterionLdrFlip},
            {"mean_flip_ldr_met", ldr},
            {"mean_flip_below", kSequenceCriterionFlip},
            {"mean_flip_met", hdr},
            {"relative_rmse_below", kSequenceCriterionRelativeRmse},
            {"relative_rmse_met", rel},
            {"relied_on", "mean_flip_ldr"},
            {"met", ldr && hdr && rel},
            {"still_golden_criterion",
             {{"mean_flip_below", kCriterionFlip},
              {"relative_rmse_below", kCriterionRelativeRmse},
              {"mean_flip_met", worst_flip < kCriterionFlip},
              {"relative_rmse_met", worst_rel < kCriterionRelativeRmse},
              {"met", worst_flip < kCriterionFlip && worst_rel < kCriterionRelativeRmse}}},
            {"justification",
             "the temporal suite scores each specular_aa variant by LDR-FLIP against this truth: 0.035 and more (off on "
             "sphere_field, fragment path); its 8x8-ray reference sequence, reported beside them, is 0.0176 from it. An "
             "LDR-FLIP bound below 0.002 (under 6 % of the smallest variant distance, 11 % of the reference's) cannot "
             "change a verdict or a ranking, and is the criterion the suite relies on. HDR-FLIP and relative RMSE are "
             "bounded looser than a still golden's (0.002, 0.5 %): bumpy_sphere under sky_sun has the 1e5 sun's "
             "reflection in a few pixels (worst pixels 58-85 % between the levels), sphere_field's small spheres are "
             "mostly rim; the suite never compares the sequences' HDR radiance (renderers/reference/CONVERGENCE.md, "
             "the temporal truth's criterion)"}};
}

nlohmann::json write_truth_sequence_golden(const SequenceRequest& req) {
    const Environment env = load_environment(req.spec.env);
    const TruthSequence seq = render_truth_sequence(req.spec, env, req.frames, req.bound_frames, req.progress);
    nlohmann::json bounds = nlohmann::json::array();
    double worst_flip = 0, worst_ldr = 0, worst_rel = 0;
    for (size_t k = 0; k < seq.bound_frames.size(); ++k) {
        const cv::Mat& a = seq.frames[size_t(seq.bound_frames[k])];
        const double hdr = compute_flip_hdr(seq.finer[k], a, FlipOptions{}).mean;
        const double ldr = compute_flip_ldr(display_transform(seq.finer[k]), display_transform(a), FlipOptions{}).mean;
        nlohmann::json b = seq.bounds[k].json();
        b.erase("per_sphere");
        b["frame"] = seq.bound_frames[k];
        b["mean_flip"] = hdr;
        b["mean_flip_ldr"] = ldr;
        bounds.push_back(b);
        worst_flip = std::max(worst_flip, hdr), worst_ldr = std::max(worst_ldr, ldr);
        worst_rel = std::max(worst_rel, seq.bounds[k].relative_rmse);
    }
    cv::Mat strip;
    cv::vconcat(seq.frames, strip);
    const std::string portable = portable_env_spec(req.spec);
    nlohmann::json meta = {
        {"scene", req.spec.scene},
        {"options", req.spec.options.canonical()},
        {"frames", req.frames},
        {"width", seq.frames.front().cols},
        {"height", seq.frames.front().rows},
        {"layout", "frames stacked vertically: frame f is rows f*height .. (f+1)*height-1"},
        {"env", {{"spec", portable}, {"content_hash", env.content_hash}, {"negatives_clamped", env.negatives_clamped}}},
        {"integrator", "quadrature"},
        {"deterministic", true},
        {"accuracy", seq.accuracy.json()},
        {"error_bound",
         {{"definition", "each bound frame against its render at the finer level (every tolerance / 2, guard / sqrt 2, "
                         "one more footprint bound level): relative_rmse and worst_pixel as in a golden's bound, mean_flip = "
                         "HDR-FLIP, mean_flip_ldr = LDR-FLIP of the display-transformed frames (the temporal suite's metric)"},
          {"frames", bounds},
          {"relative_rmse_max", worst_rel},
          {"mean_flip_max", worst_flip},
          {"mean_flip_ldr_max", worst_ldr},
          {"criterion", sequence_criterion(worst_ldr, worst_flip, worst_rel)}}},
        {"threads", seq.threads},
        {"time_s", seq.seconds},
        {"command", req.command},
        {"date", utc_now_iso()},
        {"image", std::filesystem::path(req.out_exr).filename().string()},
        {"channels", "R,G,B float32 linear"}};
    GoldenStore::write_golden(req.out_exr, strip, meta);
    return meta;
}

} // namespace iblcheck::truth
