// The CPU ground-truth integrator (method `reference`): an independent Monte Carlo evaluation of
//   L_o(v) = ∫_Ω f(l, v) L_env(l) (n·l)⁺ dl
// with f exactly material_model.h and L_env the full-resolution equirect with bilinear lookups
// (environment.h). No Vulkan, no shader code, no prefiltering: nothing shared with the methods it judges
// except the scene/environment definitions and the model's equations.
//
// Estimator (per camera sub-sample; `spp` of them per pixel):
//   * Pixel: stratified sub-pixel positions (dimension pair 0 of an Owen-scrambled Sobol sequence);
//     a sub-sample that misses every sphere contributes black, so silhouettes are anti-aliased.
//   * Lighting: multiple importance sampling, power heuristic (β = 2), one sample from each of two
//     strategies over the WHOLE BRDF (diffuse + specular evaluated together for every sample):
//       (a) BRDF sampling: with probability p_s sample the GGX visible-normal distribution (Heitz 2018,
//           "Sampling the GGX Distribution of Visible Normals"; pdf(l) = D(h)·G1(v)/(4 n·v) with the
//           Smith G1 = 2n·v/(n·v + √(α² + (1−α²)(n·v)²))), else the cosine-weighted hemisphere
//           (pdf = n·l/π); the strategy's pdf is the mixture p_s·pdf_vndf + (1−p_s)·pdf_cos.
//           p_s = spec/(spec+diff) with spec = mean_c Schlick(F0_c, n·v), diff = mean_c (1−m)·c_c.
//       (b) environment sampling: a piecewise-constant 2D distribution over the equirect pixels
//           ∝ luminance·(solid angle of the pixel) (marginal rows, conditional columns), where the
//           luminance is taken as the 3x3 maximum around each pixel so the distribution covers the
//           bilinear footprint of bright pixels (the sun). The pixel's solid angle is the exact
//           (2π/W)(cos θ_top − cos θ_bottom) rather than sin θ_centre·(2π/W)(π/H), and the direction is
//           placed uniformly in SOLID ANGLE inside the pixel (cos θ uniform, φ uniform), so
//           pdf(ω) = P_pixel / Ω_pixel — constant per pixel, no 1/sin θ spike at the poles. (Uniform-in-uv
//           placement, pdf = p(u,v)·W·H/(2π² sin θ), was measured to double the noise of upward-facing
//           normals in a constant environment.)
//   * Mirror limit: for α < 1e-4 (roughness < 0.01, in practice r = 0) the specular lobe is the delta
//     F(n·v)·L(reflect(v)) — one lookup, exact — and MIS (a)+(b) covers the diffuse lobe only.
//     No α clamp anywhere else.
//   * n·v is clamped to ≥ 1e-5 (only the last sliver of the silhouette is affected).
//   * No occlusion or inter-reflection between spheres: the integral is image-based lighting, the one
//     every method approximates.
//   * Random numbers: per pixel, hash(seed, x, y) seeds Owen-scrambled, index-shuffled Sobol (0,2)
//     pairs (Burley 2020, "Practical Hash-based Owen Scrambling"): no shared RNG state, so the image is
//     bit-identical for any thread count and every run.
//
// Options (TestSpec.options; unknown keys are ignored — they may belong to other methods):
//   roughness, metallic, base_color (scene_option_keys), spp (default 256), seed (default 0),
//   threads (0 = hardware concurrency), env_rotation (degrees about +Y), lobes = all|diffuse|specular
//   (debug/test: evaluate only that lobe of the model).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "renderers/environments/environment.h"
#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"

namespace iblcheck {

inline constexpr int kReferenceDefaultSpp = 256;

// Renders spec (scene built from spec.scene/options, environment loaded from spec.env).
RenderResult render_reference(const TestSpec& spec);
// Same with an environment given by the caller (tests, synthetic panoramas); spec.env is only recorded.
RenderResult render_reference(const TestSpec& spec, const Environment& env);

// As above, plus the per-pixel coverage (fraction of sub-samples that hit a sphere, CV_32FC1).
struct ReferenceRender {
    RenderResult result;
    cv::Mat coverage;
};
ReferenceRender render_reference_full(const TestSpec& spec, const Environment* env = nullptr);

// Noise floor of the reference at `spp`: two renders with independent seeds (seed and seed + 1 where
// seed is the spec's, default 0), compared over covered pixels (coverage > 0):
//   relative_rmse = sqrt(mean over covered pixels and channels of (a − b)² / (m² + 0.01)), m = (a + b)/2
//   (per-pixel relative error, Rousselle et al. 2011: the sun's few edge pixels do not dominate it).
// This is the between-seeds figure; each render's own RMS error against the true image is ≈ it / √2.
// mean_flip: hook for the FLIP metric (metrics/); not filled in here (the metrics library is not a
// dependency of the reference), callers holding both images may compute it.
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

namespace reference {

// Piecewise-constant environment distribution (see above), in WORLD directions (rotation applied).
class EnvDistribution {
  public:
    explicit EnvDistribution(const Environment& env);
    bool empty() const { return total_ <= 0; }
    // Samples a world direction from (u1, u2) in [0,1)²; returns its solid-angle pdf (0: no sample).
    double sample(double u1, double u2, double dir[3]) const;
    double pdf(const double dir[3]) const;

  private:
    int w_ = 0, h_ = 0;
    double total_ = 0;
    double rot_c_ = 1, rot_s_ = 0; // env -> world rotation by +rotation_deg about +Y
    std::vector<double> marginal_cdf_;    // h_ + 1
    std::vector<double> conditional_cdf_; // h_ * (w_ + 1)
    std::vector<double> prob_;            // w_ * h_, pixel probabilities
    std::vector<double> row_dcos_;        // h_: cos θ_top − cos θ_bottom of each row
};

// Owen-scrambled shuffled Sobol pair (Burley 2020) in [0,1)², deterministic in (index, seed).
void sobol_owen_2d(uint32_t index, uint32_t seed, double& x, double& y);
uint32_t hash_u32(uint32_t x);

} // namespace reference
} // namespace iblcheck
