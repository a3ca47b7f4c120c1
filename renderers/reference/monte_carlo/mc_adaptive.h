// The adaptive lighting-sample counts of the Monte Carlo integrator (monte_carlo.h, adaptive = 1): from
// a pilot pass's per-pixel ratio r = σ_L/√(μ² + 0.01) (σ_L: the per-lighting-sample standard deviation of
// the luminance over the pixel's hits, μ its value), the lighting samples per hit position of each pixel.
// The pixel's relative variance is ≈ c·σ_L²/(P·M·(μ² + 0.01)) at cost c·P·M (c = coverage), so counts
// M ∝ σ_L/√(μ² + 0.01) (3x3 max, so a ring of noisy pixels is covered whole) minimise the summed
// relative variance for the same work. Clamped to [M̄/4, adaptive_cap·M̄], M̄ = spp/P.
// Silhouette pixels (pilot coverage < 1) get at least silhouette_boost·M̄ (default 16): the mean FLIP
// between seeds is not the relative MSE — FLIP's edge detector turns a silhouette pixel's noise into
// error on both sides of the edge, background included. Measured on the studio sweep at 1024 spp:
// the silhouette ring (partially covered pixels and the background next to them) was half the mean
// FLIP (0.0099); raising adaptive_cap to 64 changed nothing (these pixels' σ_L/μ is not larger
// than their neighbours'), the boost took the FLIP to 0.0073 for 1.55x the time — better than the
// ~0.0083 that 1.55x the samples everywhere would give.
// The pilot's samples are then discarded: the counts depend on the pilot only, the main samples
// are independent of it, so each pixel's estimate stays unbiased. Tests: mc_adaptive_test.cpp.
#pragma once
#include <vector>

namespace iblcheck::reference {

struct AdaptiveLimits {
    int mean = 1;              // M̄ = spp/P, the count of every pixel without the pilot
    int cap = 16;              // adaptive_cap: at most cap·M̄
    int silhouette_boost = 16; // silhouette pixels: at least boost·M̄
};

// Lighting samples per hit position of each of the W·H pixels (row-major), from the pilot's ratio r
// (< 0: no sphere can be hit there, the count stays M̄ and is irrelevant) and its silhouette flags.
std::vector<int> adaptive_counts(const std::vector<double>& r, const std::vector<char>& silhouette, int W, int H,
                                 const AdaptiveLimits& limits);

} // namespace iblcheck::reference
