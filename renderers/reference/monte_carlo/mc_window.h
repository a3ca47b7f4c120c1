// The windowed environment strategy of the Monte Carlo integrator (env_sampling = window, the default;
// monte_carlo.h): per pixel and sphere, the environment distribution reweighted per coarse cell by a
// window K_c approximating the rest of the integrand, f·(n·l), over the directions the pixel's hits see:
//   K_c = k̄_d · cos⁺(∠(c, n₀) − δ_c − δ_p)          diffuse: Lambert's cosine, dilated
//       + F̄ · S_c / Σ S Ω   where cos⁺(…) > 0       specular, normalised to carry F̄ over the sphere
//   S_c = 1 (env_window = hemisphere, default)  or  D(cos(γ/2)), γ = max(0, ∠(c, r₀) − δ_c − 2δ_p) (lobe)
// with n₀, r₀ the normal and mirror direction at the centre of the pixel's hits on the sphere, δ_p the
// largest angle from n₀ to the normals seen in the pixel (×1.1 + 0.01), δ_c the cell's angular radius,
// k̄_d and F̄ the channel means of the Lambert term and of Schlick at n₀·v, Ω the cells' solid angles.
// ∫ k̄_d cos dl = π k̄_d is the diffuse albedo and the specular term integrates to F̄, so the two terms
// carry the lobes' relative energy. (Without the normalisation, the dilated D plateau held ~50x the
// lobe's energy and starved the diffuse lobe of dielectrics.)
// Sampling: a cell with probability P_c = K_c W_c / Σ K W (W_c: the cell's share of the luminance),
// then a pixel of it from the global distribution, so pdf_window(ω) = pdf(ω) · K_c / Σ K W. It is a
// mixture with the global distribution, weight ε = 0.1 (defensive sampling, Hesterberg 1995): every
// direction with radiance keeps a non-zero env pdf (a 5e4 sun outside a badly estimated window is
// still sampled; MIS with the BRDF strategy keeps the estimator unbiased whatever the window is, the
// window only decides how well the product L·f·cos is followed). The window is a deterministic
// function of the pixel and sphere, the same for every lighting seed.
// Measured (noise floor between seeds: mean FLIP / relative RMSE, roughness_sweep 528x96, 1024 spp):
//   studio:  global distribution 0.0117 / 1.65 %; window (64x32 cells, unnormalised lobe) 0.0099 / 1.20 %;
//            + silhouette boost 0.0073 / 0.90 %; 128x64 cells 0.0067 / 0.83 %; normalised lobe
//            0.0060 / 0.72 %; normalised hemisphere 0.0060 / 0.89 %; lobe + mis_compensation 1:
//            0.0056 / 0.68 %
//   sunrise: normalised lobe 0.0083 / 0.61 %; hemisphere 0.0084 / 0.62 %; lobe + mis_compensation 1:
//            0.0107 / 0.85 % (the compensated strategy leaves the bright sky to cosine sampling)
//   furnace (constant:1, 4096 spp): lobe 0.15 % rel. RMSE; hemisphere 0.046 %: in a constant
//   environment the lobe window competes with the exact GGX sampling instead of helping it (a metal
//   r = 0.25 furnace sphere: 0.31 % vs 0.07 % for the global distribution), the hemisphere does not.
//   Hence hemisphere by default: the same FLIP, the only criterion not met with margin, and no
//   pathological case. A Lambert sphere (lobes=diffuse, studio, 128 px, 256 spp): 2.36 % -> 1.04 %.
// (Product sampling by per-region light distributions: e.g. Conty Estevez & Kulla 2018, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting"; Clarberg et al. 2005 for the product of
// environment and BRDF.) Tests: mc_window_test.cpp.
#pragma once
#include <vector>

#include "kernel/vec3.h"
#include "renderers/reference/monte_carlo/env_distribution.h"
#include "renderers/reference/monte_carlo/mc_material.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::reference {

inline constexpr double kWindowDefensive = 0.1; // ε: the global distribution's share of the mixture

struct EnvWindow {
    bool valid = false;
    std::vector<double> marginal;    // ch + 1
    std::vector<double> conditional; // ch * (cw + 1)
    std::vector<double> factor;      // cw * ch: K_c / Σ K W (pdf_window = pdf · factor)
    std::vector<double> spec_scratch;
    // The mixture's solid-angle pdf at uv, from the global pdf there.
    double pdf(const EnvDistribution& d, double u, double v, double pdf_global) const {
        if (!valid) return pdf_global;
        return pdf_in_cell(d.cell_of_uv(u, v), pdf_global);
    }
    // The same where the direction's cell c is already known (a sample drawn from the window).
    double pdf_in_cell(int c, double pdf_global) const {
        return pdf_global * ((1 - kWindowDefensive) * factor[size_t(c)] + kWindowDefensive);
    }
};

// What pixel (x, y) sees of sphere `sphere`: n₀ and v₀, the mean normal and view direction of its hits
// (a 5x5 grid of rays over the pixel), and δ_p, the largest angle from n₀ to a hit normal (×1.1 + 0.01;
// at least 0.35 where some rays miss: rays between the grid's reach the rim). Where every grid ray misses,
// the pixel-centre ray's closest approach (a near-grazing normal). False: nothing to see.
struct PixelCone {
    Vec3d n0, v0;
    double spread = 0;
};
bool pixel_view_cone(const Scene& scene, int W, int H, int x, int y, int sphere, PixelCone& cone);

// Builds the window of pixel (x, y) for sphere `sphere` (above); invalid when the environment is empty or
// the window has no mass (the global distribution is then used alone).
void build_window(const Scene& scene, int W, int H, int x, int y, int sphere, const MatConst& M, const EnvDistribution& dist,
                  bool spec_lobe_window, EnvWindow& win);

// One environment-strategy sample from (e0, e1) in [0,1)²: the global distribution alone when the window
// is invalid, else the mixture (e1 < ε picks the global distribution, else the window's cell row from its
// marginal and column from its conditional, the remainders placing the sample inside the cell, so the
// stratification carries over). Returns the mixture's pdf of the direction dir (0: no sample), its uv.
double sample_env_window(const EnvDistribution& dist, const EnvWindow& win, double e0, double e1, double dir[3], double& u,
                         double& v);

} // namespace iblcheck::reference
