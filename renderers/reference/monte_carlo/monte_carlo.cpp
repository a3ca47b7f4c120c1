// The Monte Carlo integrator (integrator=monte_carlo; the estimator is described in monte_carlo.h): the
// render itself — options, the pilot pass of the adaptive counts, the main pass, provenance. Its pieces:
// mc_sampling.h (sampling functions), mc_shade (one lighting sample), mc_window (the windowed environment
// strategy), mc_pixel (one pixel), mc_adaptive (the counts), env_distribution (the environment's
// distribution, Sobol numbers), mc_noise_floor.cpp (the noise floor between seeds).
#include "renderers/reference/monte_carlo/monte_carlo.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "kernel/parallel_for.h"
#include "renderers/option_table.h"
#include "renderers/reference/monte_carlo/mc_adaptive.h"
#include "renderers/reference/monte_carlo/mc_pixel.h"

namespace iblcheck {

namespace {
using reference::adaptive_counts;
using reference::AdaptiveLimits;
using reference::EnvDistribution;
using reference::EnvImage;
using reference::hash_u32;
using reference::mat_const;
using reference::MatConst;
using reference::McLobes;
using reference::pixel_candidates;
using reference::PixelContext;
using reference::PixelOut;
using reference::render_pixel;
using reference::Shader;

// The integrator's options (monte_carlo.h, "Options"), read and checked once.
struct McOptions {
    int spp, seed, pattern, adaptive_cap, silhouette_boost, positions, threads;
    bool adaptive;
    std::string lobes, mis, env_sampling, env_window;
    double mis_compensation;
};

McOptions read_options(const OptionMap& o) {
    McOptions m;
    m.spp = option_int(o, "spp", "reference");
    m.seed = option_int(o, "seed", "reference");
    m.pattern = option_int(o, "pixel_pattern", "reference");
    m.adaptive = option_int(o, "adaptive", "reference") != 0;
    m.adaptive_cap = option_int(o, "adaptive_cap", "reference");
    m.silhouette_boost = option_int(o, "silhouette_boost", "reference");
    m.positions = std::clamp(o.get_int("positions").value_or(std::max(1, m.spp / 4)), 1, std::max(1, m.spp)); // the table: spp/4
    m.threads = option_int(o, "threads", "reference");
    m.lobes = option_choice(o, "lobes");
    m.mis = option_choice(o, "mis");
    m.env_sampling = option_choice(o, "env_sampling");
    m.env_window = option_choice(o, "env_window");
    m.mis_compensation = option_double(o, "mis_compensation", "reference");
    if (m.mis_compensation < 0) throw UsageError("option 'mis_compensation': must be >= 0");
    if (m.spp < 1) throw UsageError("option 'spp': must be >= 1");
    if (m.threads < 0) throw UsageError("option 'threads': must be >= 0");
    if (m.silhouette_boost < 1) throw UsageError("option 'silhouette_boost': must be >= 1");
    return m;
}

std::string estimator_description(bool window, bool lobe_window, double compensation, int silhouette_boost) {
    std::string env = std::string("environment sampling [piecewise-constant equirect distribution ~ ") +
                      (compensation > 0 ? "max(0, 3x3-max luminance - " + fmt::format("{:g}", compensation) +
                                              " x mean luminance) (MIS compensation, Karlik et al. 2019)"
                                        : std::string("3x3-max luminance")) +
                      " * solid angle, guide-table CDF inversion";
    if (window)
        env += std::string("; per pixel and sphere reweighted by 128x64 cells with a window ~ dilated cosine (diffuse) + ") +
               (lobe_window ? "GGX D about the mirror direction" : "flat hemisphere") +
               " (specular), mixed with 10 % of the unwindowed distribution";
    env += "]";
    return "sub-pixel positions: an Owen-scrambled Sobol pattern per pixel keyed by pixel_pattern (not by the "
           "lighting seed); lighting per position: MIS (power heuristic, 1 sample each) of "
           "BRDF sampling [mixture of GGX VNDF (Heitz 2018) with p_s = F/(F+diffuse) clamped to [0.1,0.9], and "
           "cosine hemisphere] and " +
           env + ", whole BRDF per sample; adaptive lighting-sample counts from a discarded pilot, silhouette pixels at least " +
           std::to_string(silhouette_boost) +
           "x the mean; alpha < 1e-4 treated as a mirror delta F(n.v) L(reflect); bilinear env lookups; no "
           "inter-sphere occlusion";
}

// Each row's pixels are written by that row alone, from hashes of the pixel and the seed: the same
// bits for any thread count. A worker keeps its candidates and windows as scratch.
reference::PixelScratch pixel_scratch() { return {}; }

// The pilot pass of the adaptive counts (mc_adaptive.h): its own lighting keys, independent of the main
// pass's; min(P, 32) positions of the pattern × 2 lighting samples per pixel. Returns the counts; adds the
// pilot's lighting samples to `pilot_samples`.
std::vector<int> pilot_counts(const PixelContext& ctx, const McOptions& opt, uint32_t seed_hash, uint32_t pattern_hash,
                              int threads, int m_mean, long& pilot_samples) {
    const int W = ctx.W, H = ctx.H;
    std::vector<double> r(size_t(W) * H, -1.0);
    std::vector<char> partial(size_t(W) * H, 0);
    const uint32_t pilot_hash = hash_u32(seed_hash ^ 0x3c6ef372u);
    const int pilot_pos = std::min(opt.positions, 32);
    std::atomic<long> pilot_n{0};
    parallel_for(H, threads, pixel_scratch, [&](int y, reference::PixelScratch& scratch) {
        long f = 0;
        for (int x = 0; x < W; ++x) {
            const uint32_t pix = hash_u32(uint32_t(y) * uint32_t(W) + uint32_t(x));
            pixel_candidates(ctx.scene, W, H, x, y, scratch.cand);
            if (scratch.cand.empty()) continue;
            PixelOut po =
                render_pixel(ctx, x, y, pilot_pos, 2, hash_u32(pattern_hash ^ pix), hash_u32(pilot_hash ^ pix), scratch, f);
            double mu = po.coverage * po.lum_mean;
            r[size_t(y) * W + x] = std::sqrt(po.lum_var) / std::sqrt(mu * mu + 0.01);
            if (po.coverage < 1) partial[size_t(y) * W + x] = 1; // silhouette (or a sliver the pilot missed)
            pilot_n += long(std::lround(po.coverage * pilot_pos)) * 2;
        }
    });
    pilot_samples = pilot_n;
    return adaptive_counts(r, partial, W, H, AdaptiveLimits{m_mean, opt.adaptive_cap, opt.silhouette_boost});
}

// The main pass: every pixel with its count; the image, coverage, and environment lookups per row.
void main_pass(const PixelContext& ctx, const McOptions& opt, uint32_t seed_hash, uint32_t pattern_hash, int threads,
               const std::vector<int>& counts, cv::Mat& image, cv::Mat& coverage, std::vector<long>& row_fetches) {
    const int W = ctx.W;
    parallel_for(ctx.H, threads, pixel_scratch, [&](int y, reference::PixelScratch& scratch) {
        long fetches = 0;
        for (int x = 0; x < W; ++x) {
            const uint32_t pix = hash_u32(uint32_t(y) * uint32_t(W) + uint32_t(x));
            const uint32_t pix_seed = hash_u32(seed_hash ^ pix);
            const uint32_t pat_seed = hash_u32(pattern_hash ^ pix);
            pixel_candidates(ctx.scene, W, ctx.H, x, y, scratch.cand);
            PixelOut po = render_pixel(ctx, x, y, opt.positions, counts[size_t(y) * W + x], pat_seed, pix_seed, scratch, fetches);
            auto& px = image.at<cv::Vec3f>(y, x);
            for (int i = 0; i < 3; ++i) px[i] = float(po.rgb[i]);
            coverage.at<float>(y, x) = float(po.coverage);
        }
        row_fetches[y] = fetches;
    });
}

// The render's provenance (what a golden's sidecar records of it).
nlohmann::json provenance(const TestSpec& spec, const McOptions& opt, const Environment& env, int W, int H, int threads,
                          double lit_per_covered, long pilot_samples, double fetches_per_pixel, double total_s) {
    return {
        {"method", "reference"},
        {"scene", spec.scene},
        {"options", spec.options.canonical()},
        {"width", W},
        {"height", H},
        {"spp", opt.spp},
        {"seed", opt.seed},
        {"pixel_pattern", opt.pattern},
        {"adaptive", opt.adaptive},
        {"positions", opt.positions},
        {"lighting_samples_per_covered_pixel", lit_per_covered},
        {"pilot_samples", pilot_samples},
        {"threads", threads},
        {"lobes", opt.lobes},
        {"mis", opt.mis},
        {"env_sampling", opt.env_sampling},
        {"env_window", opt.env_window},
        {"mis_compensation", opt.mis_compensation},
        {"env",
         {{"spec", env.spec.empty() ? spec.env : env.spec},
          {"content_hash", env.content_hash},
          // the file's name, not its path: provenance holds no machine paths (issue 15)
          {"source_file", std::filesystem::path(env.source_path).filename().string()},
          {"width", env.equirect.cols},
          {"height", env.equirect.rows},
          {"negatives_clamped", env.negatives_clamped},
          {"rotation_deg", env.rotation_deg}}},
        {"estimator", estimator_description(opt.env_sampling == "window", opt.env_window == "lobe", opt.mis_compensation,
                                            opt.adaptive ? opt.silhouette_boost : 1)},
        {"texture_fetches_per_pixel", fetches_per_pixel},
        {"time_s", total_s},
    };
}

// Lighting samples the main pass spent per covered pixel (partially covered pixels have fewer hits).
double lit_per_covered_pixel(const cv::Mat& coverage, const std::vector<int>& counts, int positions) {
    long main_samples = 0, covered = 0;
    for (int y = 0; y < coverage.rows; ++y)
        for (int x = 0; x < coverage.cols; ++x)
            if (coverage.at<float>(y, x) > 0)
                main_samples += long(std::lround(coverage.at<float>(y, x) * positions)) * counts[size_t(y) * coverage.cols + x],
                    ++covered;
    return covered ? double(main_samples) / double(covered) : 0.0;
}
} // namespace

ReferenceRender render_reference_full(const TestSpec& spec, const Environment* env_in) {
    auto t0 = std::chrono::steady_clock::now();
    Scene scene = build_scene(spec.scene, spec.options);
    const McOptions opt = read_options(spec.options);
    const McLobes lobes = opt.lobes == "diffuse" ? McLobes::diffuse : opt.lobes == "specular" ? McLobes::specular : McLobes::all;

    Environment env = env_in ? *env_in : load_environment(spec.env);
    if (spec.options.has("env_rotation")) env.rotation_deg = float(option_double(spec.options, "env_rotation", "reference"));
    EnvDistribution dist(env, opt.mis_compensation);
    cv::Mat equirect = env.equirect.isContinuous() ? env.equirect : env.equirect.clone();
    EnvImage img(equirect);

    const int W = spec.width > 0 ? spec.width : scene.width;
    const int H = spec.height > 0 ? spec.height : scene.height;
    int threads = opt.threads;
    threads = std::min(resolve_threads(threads), H); // as the provenance records it

    cv::Mat image(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
    cv::Mat coverage(H, W, CV_32FC1, cv::Scalar(0));
    std::vector<long> row_fetches(H, 0);
    Shader S{img, dist, lobes, opt.mis == "power", opt.env_sampling == "window"};
    std::vector<MatConst> mats;
    for (const auto& sp : scene.spheres) mats.push_back(mat_const(sp.material, lobes));
    const PixelContext ctx{scene, W, H, S, mats, opt.env_window == "lobe"};
    const uint32_t seed_hash = hash_u32(uint32_t(opt.seed) * 0x9e3779b9u + 0x85ebca6bu);
    // The sub-pixel pattern has its own key: renders with different lighting seeds integrate the
    // pixel footprint with the same points, so their difference is lighting noise only (reference.h).
    const uint32_t pattern_hash = hash_u32(uint32_t(opt.pattern) * 0x2545f491u + 0x6a09e667u);
    auto t1 = std::chrono::steady_clock::now();

    // Lighting samples per hit position: M̄ = spp/P everywhere, or adaptive (mc_adaptive.h).
    const int m_mean = std::max(1, int(std::lround(double(opt.spp) / opt.positions)));
    long pilot_samples = 0;
    const std::vector<int> counts = opt.adaptive ? pilot_counts(ctx, opt, seed_hash, pattern_hash, threads, m_mean, pilot_samples)
                                                 : std::vector<int>(size_t(W) * H, m_mean);
    main_pass(ctx, opt, seed_hash, pattern_hash, threads, counts, image, coverage, row_fetches);
    auto t2 = std::chrono::steady_clock::now();
    long total_fetches = 0;
    for (long f : row_fetches) total_fetches += f;

    ReferenceRender out;
    out.coverage = coverage;
    RenderResult& r = out.result;
    r.image = image;
    double ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    r.timings.push_back({"reference_cpu", ms, false, false});
    r.texture_fetches_per_pixel = double(total_fetches) / (double(W) * H);
    r.provenance = provenance(spec, opt, env, W, H, threads, lit_per_covered_pixel(coverage, counts, opt.positions),
                              pilot_samples, r.texture_fetches_per_pixel, std::chrono::duration<double>(t2 - t0).count());
    return out;
}

} // namespace iblcheck
