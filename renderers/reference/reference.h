// The reference method (`reference`): the ground truth every other method is judged against. Contract:
//   * The image of a scene of spheres under distant light (image-based lighting, no occlusion or
//     inter-reflection), each pixel the average over its footprint of the outgoing radiance
//     L_o(n, v) = ∫ f(l, v) L(l) (n·l)⁺ dl, with f exactly material_model.h (Lambert + GGX +
//     height-correlated Smith + Schlick, no split sum), L the environment's equirect with its
//     bilinear filter (environment.h), n the sphere's normal (bumped: scene.h, bump_normal) and n·v
//     clamped to ≥ 1e-5. A mirror (roughness < 0.01) is the delta F(n·v)·L(reflect(v)). Background: 0.
//   * Nothing shared with the methods it judges except the scene/environment definitions and the
//     model's equations: no shader code, no prefiltered cubes of the mobile pipeline.
//   * Default: the quadrature truth (truth_renderer.h), deterministic (bit-identical for any thread
//     count), computed at two refinement levels; the image is the finer level and the provenance
//     carries the error bound — the levels' difference (relative RMSE, per sphere, worst pixel; FLIP
//     where the metrics are linked: truth_golden.h). Needs the orthographic camera (every built-in
//     scene), as each sphere's radiance is tabulated over its normals (one view per sphere).
//   * integrator=monte_carlo, or any spp=N: the previous Monte Carlo integrator (monte_carlo.h), whose
//     error is known only statistically (noise floor between seeds); it refuses bumped spheres.
//   * Options: the scene's (roughness, metallic, base_color, frame, bump_*), env_rotation, threads
//     (0 = all), lobes = all|diffuse|specular (tests), truth_tolerance (the coarser level's per-pixel
//     relative tolerance, default 1e-3), integrator; the Monte Carlo integrator's own (monte_carlo.h).
// Method, measurements and their derivations: renderers/reference/CONVERGENCE.md.
#pragma once
#include "renderers/reference/monte_carlo/monte_carlo.h"
#include "renderers/reference/quadrature/truth_renderer.h"

namespace iblcheck {

// Renders spec (scene built from spec.scene/options, environment loaded from spec.env).
RenderResult render_reference(const TestSpec& spec);
// Same with an environment given by the caller (tests, synthetic panoramas); spec.env is only recorded.
RenderResult render_reference(const TestSpec& spec, const Environment& env);
// Whether spec selects the quadrature truth (integrator=quadrature, or no integrator and no spp).
bool uses_quadrature(const TestSpec& spec);

} // namespace iblcheck
