// One pixel of the Monte Carlo integrator (monte_carlo.h, "Pixel footprint"): P sub-pixel positions from
// the pixel's pattern key, and at each that hits a sphere M lighting samples (mc_shade.h); with the
// per-pixel sphere culling that keeps the intersection loop short. Tests: mc_pixel_test.cpp.
#pragma once
#include <cstdint>
#include <vector>

#include "kernel/vec3.h"
#include "renderers/reference/monte_carlo/mc_material.h"
#include "renderers/reference/monte_carlo/mc_shade.h"
#include "renderers/reference/monte_carlo/mc_window.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::reference {

// Spheres that any ray through pixel (x, y) can hit (conservative), so the per-sample intersection
// loop skips the others. Orthographic: distance of the centre from the pixel-centre ray ≤ radius +
// half the pixel diagonal. Perspective: angle between the centre ray and the sphere ≤ its angular
// radius + the largest centre-to-corner ray angle.
void pixel_candidates(const Scene& scene, int W, int H, int x, int y, std::vector<int>& out);

// Nearest hit among the candidate spheres, with scene.cpp's intersect() arithmetic and rounding (a float
// unit normal): false when none is hit.
bool intersect_candidates(const Scene& scene, const std::vector<int>& cand, Vec3f origin, Vec3f dir, int& sphere, Vec3d& normal);

// What every pixel of a render shares.
struct PixelContext {
    const Scene& scene;
    int W, H;
    const Shader& shader;
    const std::vector<MatConst>& mats; // per sphere
    bool lobe_window;                  // env_window = lobe (else hemisphere)
};

// The pixel mean, its coverage (the fraction of positions that hit a sphere), and (for the pilot of the
// adaptive counts) the mean and sample variance of the per-lighting-sample luminance over the hits.
struct PixelOut {
    double rgb[3] = {0, 0, 0};
    double coverage = 0, lum_mean = 0, lum_var = 0;
};

// A worker's buffers, kept from pixel to pixel: the pixel's candidate spheres (pixel_candidates) and their
// windows. A window is four arrays of the environment's cells (8192 doubles each at 128x64 cells),
// allocated and cleared for every pixel before (perf: the clearing alone was 3 % of a 64-spp render).
struct PixelScratch {
    std::vector<int> cand;
    std::vector<EnvWindow> windows;
    std::vector<char> built;
};

// Pixel (x, y) among the spheres scratch.cand: P sub-pixel positions from the pattern key `pattern` (the
// same for every lighting seed); at each position that hits a candidate sphere, M lighting samples (Sobol
// indices k·M .. k·M + M − 1 of the pixel's lighting sequence, key `pixel_seed`). A sphere's window
// (mc_window.h) is built at its first hit in the pixel.
PixelOut render_pixel(const PixelContext& ctx, int x, int y, int P, int M, uint32_t pattern, uint32_t pixel_seed,
                      PixelScratch& scratch, long& fetches);

} // namespace iblcheck::reference
