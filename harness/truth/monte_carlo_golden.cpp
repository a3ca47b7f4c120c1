// One Monte Carlo golden and its sidecar (monte_carlo_golden.h). The sidecar's fields are those the
// retired iblcheck_reference_tool wrote with --noise-floor, unchanged.
#include "harness/truth/monte_carlo_golden.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>

#include "harness/golden_store.h"
#include "harness/truth/truth_golden.h"
#include "metrics/flip.h"

namespace iblcheck::reference {

// The golden writers' shared pieces (truth_golden.h): the same criterion and environment spelling as the
// quadrature's goldens (both write through GoldenStore::write_golden).
using truth::kCriterionFlip;
using truth::kCriterionRelativeRmse;
using truth::portable_env_spec;

namespace {
// Issue 5's convergence criterion on the noise floor between the two seeds, stated with its verdict.
nlohmann::json noise_floor_json(const NoiseFloor& nf, double flip) {
    nlohmann::json j = {{"relative_rmse", nf.relative_rmse},
                        {"definition", "sqrt(mean((a-b)^2 / (m^2 + 0.01))), m = (a+b)/2, over covered "
                                       "pixels and channels; a/b = renders with seeds a/b"},
                        {"mean_value", nf.mean_value},
                        {"covered_pixels", nf.covered_pixels},
                        {"seeds", {nf.seed_a, nf.seed_b}},
                        {"mean_flip", flip},
                        {"what_differs", "the lighting random numbers only: both renders integrate each pixel's "
                                         "footprint with the same sub-pixel pattern (pixel_pattern), see reference.h"}};
    j["criterion"] = {{"mean_flip_below", kCriterionFlip},
                      {"relative_rmse_below", kCriterionRelativeRmse},
                      {"mean_flip_met", flip < kCriterionFlip},
                      {"relative_rmse_met", nf.relative_rmse < kCriterionRelativeRmse},
                      {"met", flip < kCriterionFlip && nf.relative_rmse < kCriterionRelativeRmse}};
    return j;
}
} // namespace

MonteCarloGoldenWritten write_monte_carlo_golden(const MonteCarloGoldenRequest& req) {
    const auto t0 = std::chrono::steady_clock::now();
    TestSpec spec = req.spec;
    spec.options.set("seed", std::to_string(req.seed));
    MonteCarloGoldenWritten out;
    out.noise = measure_noise_floor(spec, req.spp);
    const NoiseFloor& nf = out.noise;
    const FlipResult fr = compute_flip_hdr(nf.image_a, nf.image_b, FlipOptions{});
    out.flip_errmap = fr.errmap;
    nlohmann::json& meta = out.meta;
    meta["noise_floor"] = noise_floor_json(nf, fr.mean);
    out.criterion_met = meta["noise_floor"]["criterion"]["met"].get<bool>();
    meta["seeds"] = {nf.seed_a, nf.seed_b};
    meta["provenance"] = nf.provenance_a;
    spec.options.set("spp", std::to_string(req.spp));
    const double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const Environment env = load_environment(spec.env);
    meta["scene"] = spec.scene;
    meta["options"] = spec.options.canonical();
    meta["width"] = nf.image_a.cols;
    meta["height"] = nf.image_a.rows;
    meta["env"] = {
        {"spec", portable_env_spec(spec)}, {"content_hash", env.content_hash}, {"negatives_clamped", env.negatives_clamped}};
    meta["spp"] = req.spp;
    meta["time_s"] = time_s;
    meta["command"] = req.command;
    meta["date"] = utc_now_iso();
    meta["image"] = std::filesystem::path(req.out_exr).filename().string(); // beside the sidecar: no machine path
    meta["channels"] = "R,G,B float32 linear";
    GoldenStore::write_golden(req.out_exr, nf.image_a, meta);
    return out;
}

std::string noise_floor_by_tile(const MonteCarloGoldenWritten& g, int tile_w, int tile_h) {
    const NoiseFloor& nf = g.noise;
    const cv::Mat& err = g.flip_errmap;
    std::string s =
        fmt::format("noise floor per {}x{} tile: mean FLIP / relative RMSE (tiles with covered pixels)\n", tile_w, tile_h);
    for (int ty = 0; ty < nf.image_a.rows; ty += tile_h) {
        for (int tx = 0; tx < nf.image_a.cols; tx += tile_w) {
            const cv::Rect rc(tx, ty, std::min(tile_w, nf.image_a.cols - tx), std::min(tile_h, nf.image_a.rows - ty));
            const double rel = relative_rmse(nf.image_a(rc), nf.image_b(rc), nf.coverage(rc));
            s += fmt::format(" {:.4f}/{:.2f}%", cv::mean(err(rc))[0], 100 * rel);
        }
        s += "\n";
    }
    const cv::Mat full = nf.coverage >= 1.0f, part = (nf.coverage > 0.0f) & (nf.coverage < 1.0f);
    cv::Mat fullf, partf;
    full.convertTo(fullf, CV_32F, 1.0 / 255), part.convertTo(partf, CV_32F, 1.0 / 255);
    s += fmt::format("fully covered pixels: {}, FLIP {:.4f}, relative RMSE {:.2f}%; partially covered: {}, FLIP {:.4f}, "
                     "relative RMSE {:.2f}%\n",
                     cv::countNonZero(full), cv::mean(err, full)[0], 100 * relative_rmse(nf.image_a, nf.image_b, fullf),
                     cv::countNonZero(part), cv::mean(err, part)[0], 100 * relative_rmse(nf.image_a, nf.image_b, partf));
    return s;
}

} // namespace iblcheck::reference
