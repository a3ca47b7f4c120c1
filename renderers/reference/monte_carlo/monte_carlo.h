// The Monte Carlo integrator (method `reference` with integrator=monte_carlo, or any `spp=N`): the previous
// ground truth, kept as an independent check of the quadrature truth (reference.h). A Monte Carlo
// evaluation of
//   L_o(v) = ∫_Ω f(l, v) L_env(l) (n·l)⁺ dl
// with f exactly material_model.h and L_env the full-resolution equirect with bilinear lookups
// (environment.h). No Vulkan, no shader code, no prefiltering: nothing shared with the methods it judges
// except the scene/environment definitions and the model's equations.
//
// Estimator (`spp` = lighting samples per pixel, nominal):
//   * Pixel footprint: P sub-pixel positions (option positions, default spp/4, at most spp), an Owen-scrambled
//     Sobol pattern per pixel keyed by the option pixel_pattern and the pixel, NOT by the lighting seed:
//     renders with different seeds integrate the footprint with the same points, so the between-seeds
//     noise floor measures lighting noise only. (Measured: at 256 spp the FLIP heatmap between seeds
//     shows the silhouette ring with either keying — the ring is lighting noise of partially covered
//     pixels, few hits carrying all the lighting noise of a dim pixel — see the adaptive counts below.)
//     The pattern's own error (a P-point quadrature of the footprint, which the noise floor cannot see)
//     is measured by comparing two patterns on the worst case, a mirror sphere under studio (sharp light
//     edges in the reflection; lobes=specular makes the shading deterministic per position): relative
//     RMSE 1.2 % / 0.49 % / 0.04 % / 0.009 % and mean FLIP 0.0026 / 0.0011 / 0.0005 / 0.0002 at
//     P = 256 / 1024 / 4096 / 16384 — hence P = spp/4, not a fixed small P (tests/
//     test_reference_integrator.cpp, PixelPatternErrorIsSmall; CONVERGENCE.md).
//     A position that misses every sphere contributes black, so silhouettes are anti-aliased.
//   * Lighting samples per hit position: M (Sobol indices k·M .. k·M + M − 1 of the pixel's lighting
//     sequence for position k, so the P·M points of an interior pixel form one stratified sequence).
//     M̄ = spp/P (4 by default). adaptive = 1 (default): a pilot pass with its own random numbers
//     (the first 32 positions × 2 samples)
//     estimates per pixel r = σ_L/√(μ² + 0.01) (σ_L: per-sample std of the luminance over the hits,
//     μ: the pixel's value — the relative-RMSE metric's normalisation); M ∝ r (3x3 max), mean spp/P,
//     clamped to [M̄/4, adaptive_cap·M̄] (cap 16). The pilot's samples are discarded, so the counts are
//     independent of the main samples and every pixel's estimate stays unbiased (Owen-scrambled Sobol
//     is unbiased for any count). adaptive = 0: M = spp/P everywhere.
//   * Lighting (each sample): multiple importance sampling, power heuristic (β = 2), one sample from each of two
//     strategies over the WHOLE BRDF (diffuse + specular evaluated together for every sample):
//       (a) BRDF sampling: with probability p_s sample the GGX visible-normal distribution (Heitz 2018,
//           "Sampling the GGX Distribution of Visible Normals"; pdf(l) = D(h)·G1(v)/(4 n·v) with the
//           Smith G1 = 2n·v/(n·v + √(α² + (1−α²)(n·v)²))), else the cosine-weighted hemisphere
//           (pdf = n·l/π); the strategy's pdf is the mixture p_s·pdf_vndf + (1−p_s)·pdf_cos. The lobe is
//           chosen by splitting the second Sobol coordinate at p_s (rescaled), not by a separate number,
//           so each lobe keeps a stratified share of the points.
//           p_s = spec/(spec+diff) with spec = mean_c Schlick(F0_c, n·v), diff = mean_c (1−m)·c_c.
//       (b) environment sampling: a piecewise-constant 2D distribution over the equirect pixels
//           ∝ luminance·(solid angle of the pixel) (marginal rows, conditional columns), where the
//           luminance is taken as the 3x3 maximum around each pixel so the distribution covers the
//           bilinear footprint of bright pixels (the sun). The pixel's solid angle is the exact
//           (2π/W)(cos θ_top − cos θ_bottom) rather than sin θ_centre·(2π/W)(π/H), and the direction is
//           placed uniformly in SOLID ANGLE inside the pixel (cos θ uniform, φ uniform), so
//           pdf(ω) = P_pixel / Ω_pixel — constant per pixel, no 1/sin θ spike at the poles. (Uniform-in-uv
//           placement, pdf = p(u,v)·W·H/(2π² sin θ), was measured to double the noise of upward-facing
//           normals in a constant environment.) The CDFs are inverted through guide tables (cutpoint
//           method: O(1) expected, still monotone, so the Sobol stratification carries over to the
//           environment — an alias table would lose it); the per-pixel pdf is stored (float) and shared by
//           sample() and pdf(), so the estimator sees exactly the density it samples.
//           Windowed (env_sampling = window, the default): per pixel and sphere, that distribution is
//           reweighted per coarse cell (128x64 cells of the equirect) by a window approximating the rest
//           of the integrand over the hemisphere the pixel's normals see — the dilated cosine for the
//           diffuse lobe plus, for the specular lobe, a flat hemisphere (env_window = hemisphere, default)
//           or GGX's D about the mirror direction (env_window = lobe) — and mixed with 10 % of the plain
//           distribution (defensive), so no direction with radiance has a zero env pdf. Rationale and
//           measurements: mc_window.h and CONVERGENCE.md. mis_compensation = κ samples
//           max(0, Y − κȲ) instead of Y (Karlík et al. 2019); default 0 (measured worse on sunrise).
//   * Mirror limit: for α < 1e-4 (roughness < 0.01, in practice r = 0) the specular lobe is the delta
//     F(n·v)·L(reflect(v)) — one lookup, exact — and MIS (a)+(b) covers the diffuse lobe only.
//     No α clamp anywhere else.
//   * n·v is clamped to ≥ 1e-5 (only the last sliver of the silhouette is affected).
//   * No occlusion or inter-reflection between spheres: the integral is image-based lighting, the one
//     every method approximates.
//   * Random numbers: per pixel, hash(seed, x, y) seeds Owen-scrambled, index-shuffled Sobol (0,2)
//     pairs (Burley 2020, "Practical Hash-based Owen Scrambling"); hash(pixel_pattern, x, y) the
//     positions: no shared RNG state, and the adaptive counts are a deterministic function of the pilot,
//     so the image is bit-identical for any thread count and every run.
//   * Speed (measured with perf; 2-core machine, roughness_sweep/studio 64 spp, 1 thread: 2.8 s -> 2.0 s
//     before the adaptive counts): per-pixel sphere culling (conservative pixel-cone test, then the
//     intersection arithmetic of scene.cpp over the candidates), per-sphere material constants, one
//     direction -> uv conversion shared by the pdf and the bilinear lookup (and none for environment
//     samples, whose uv is known), guide-table CDF inversion, stored per-pixel pdf. Convergence table
//     (spp vs noise floor vs time): renderers/reference/CONVERGENCE.md.
//
// Options (TestSpec.options; unknown keys are ignored — they may belong to other methods):
//   roughness, metallic, base_color (scene_option_keys), spp (default 256), seed (default 0; the
//   lighting random numbers), pixel_pattern (default 0; the sub-pixel positions), positions (default
//   spp/4), adaptive (default 1), adaptive_cap (default 16), mis = power|balance, threads (0 = hardware
//   concurrency), env_rotation (degrees about +Y), lobes = all|diffuse|specular (debug/test: evaluate
//   only that lobe of the model), env_sampling = window|global, env_window = hemisphere|lobe,
//   mis_compensation (default 0), silhouette_boost (default 16: lighting samples of silhouette pixels
//   at least this many times the mean, with adaptive = 1).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "renderers/environments/environment.h"
#include "renderers/reference/monte_carlo/env_distribution.h"
#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"

namespace iblcheck {

// Renders spec with the Monte Carlo integrator (the environment loaded from spec.env unless given), and
// the per-pixel coverage (fraction of sub-samples that hit a sphere, CV_32FC1).
struct ReferenceRender {
    RenderResult result;
    cv::Mat coverage;
};
ReferenceRender render_reference_full(const TestSpec& spec, const Environment* env = nullptr);

// Noise floor of the reference at `spp`: two renders with independent lighting seeds (seed and seed + 1
// where seed is the spec's, default 0; the same pixel_pattern), compared over covered pixels (coverage > 0):
//   relative_rmse = sqrt(mean over covered pixels and channels of (a − b)² / (m² + 0.01)), m = (a + b)/2
//   (per-pixel relative error, Rousselle et al. 2011: the sun's few edge pixels do not dominate it).
// This is the between-seeds figure; each render's own RMS error against the true image is ≈ it / √2.
// mean_flip: hook for the FLIP metric (metrics/); not filled in here (the metrics library is not a
// dependency of the reference), callers holding both images may compute it (monte_carlo_golden.h does).
// Issue 5's criterion: mean FLIP < 0.002 and relative RMSE < 0.005 between the seeds. What each
// golden reaches, and at what cost, is in CONVERGENCE.md and in the golden's JSON (noise_floor.criterion).
struct NoiseFloor {
    int spp = 0;
    int seed_a = 0, seed_b = 1;
    double relative_rmse = 0;
    double mean_value = 0;
    long covered_pixels = 0;
    double time_s = 0; // both renders
    std::optional<double> mean_flip;
    cv::Mat image_a, image_b;
    nlohmann::json provenance_a; // of the seed-a render
    cv::Mat coverage;
};
NoiseFloor measure_noise_floor(const TestSpec& spec, int spp);
// The comparison alone (covered pixels: coverage > 0).
double relative_rmse(const cv::Mat& a, const cv::Mat& b, const cv::Mat& coverage, double* mean_value = nullptr);

} // namespace iblcheck
