// The split-sum approximation evaluated with the quadrature truth's own machinery (option split_sum,
// the first rungs of `iblcheck explain`): every normal-table node is shaded as
//
//   L_o ≈ P(R, α)·(F0·A(n·v, α) + B(n·v, α)) + ∫ kd·L(l)(n·l)⁺ dl
//
// P(R, α) = ∫ L(l) D(h)(n·l)⁺ dl / ∫ D(h)(n·l)⁺ dl with n = v = R = reflect(v, n): the prefiltered
// radiance under Karis's n = v = r assumption (2013, "Real Shading in Unreal Engine 4"), integrated by
// the same lobe quadrature as the truth (lobe_quadrature.h, MaterialLobe::prefilter). (A, B) is the DFG
// of exactly material_model.h's specular model (GGX, height-correlated Smith V, Schlick F):
// F0·A + B = ∫ D·V·F·(n·l) dl; split_sum=env_brdf_approx takes Karis/Lazarov's EnvBRDFApprox instead
// (the GPU's renderers/shaders/env_brdf.glsl). The diffuse lobe is the truth's (Lambert at the real n).
// So the difference between the truth and split_sum=exact is the n = v = r lobe assumption alone, and
// between exact and env_brdf_approx the DFG fit alone.
#pragma once
#include "renderers/reference/quadrature/lobe_quadrature.h"
#include "renderers/reference/quadrature/truth_math.h"

namespace iblcheck::truth {

// ∫ D(h)(n·l)⁺ dl at n = v (the prefilter's normalisation), in closed form (split_sum.cpp).
double prefilter_norm(double alpha);

struct Dfg {
    double a = 0, b = 0; // F0·a + b = the specular directional albedo
};
// The exact DFG at (n·v, α) by a deterministic Gauss–Legendre product rule (split_sum.cpp): accurate
// to ~1e-6 of (a + b) (split_sum_test.cpp checks the furnace values).
Dfg dfg_exact(double nv, double alpha);
// The same from a cached table over n·v per α (cubic interpolation; what the nodes use: a node would
// otherwise cost 16k evaluations for its DFG).
Dfg dfg_exact_cached(double nv, double alpha);
// Karis 2014's EnvBRDFApprox with the published constants (env_brdf.glsl), perceptual roughness r.
Dfg env_brdf_approx(double roughness, double nv);

// The split-sum shading of one point (lobe.split_sum ≠ off), added to rgb[].
void shade_split_sum(const EnvPyramid& env, const MaterialLobe& lobe, const ShadingPoint& s, const QuadratureParams& p,
                     double rgb[3], ShadeStats* stats = nullptr);

} // namespace iblcheck::truth
