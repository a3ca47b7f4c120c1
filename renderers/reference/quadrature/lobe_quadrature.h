// The quadrature rule for one shading point: L_o(n, v) = ∫ f(l, v) L(l) (n·l)⁺ dl over the environment
// pyramid (env_pyramid.h), deterministic.
//
// A cell's one-point rule is f·cos at its luminance-weighted centroid times its exact ∫L (exact for a
// BRDF constant over the cell, second order for a smooth one; a bright compact source inside a big
// cell is evaluated where it is). Sub-texel cells use the bilinear radiance at their centre times their
// exact solid angle. Cells are refined by adaptive_refine.h from the ~22.5 degree level down to texels
// and below (to 2^-max_subtexel of a texel) until the indicators (|4 children − 1 point| per cell) sum
// to at most tolerance·(value + floor). The lobe guard forces the split of every cell that overlaps the
// GGX lobe's core (within its radius + 3w of the mirror direction) while its radius exceeds κ·w,
// w = 2α·max(n·v, 0.05) the lobe's width (2α in the plane of incidence, 2α·n·v across it): a one-point
// rule cannot see a lobe narrower than its cell. A mirror (α < 1e-4) adds F(n·v)·L(reflect(v)) exactly
// (one bilinear lookup) and integrates the diffuse lobe only.
#pragma once
#include <cstddef>

#include "renderers/reference/quadrature/env_pyramid.h"
#include "renderers/reference/quadrature/truth_math.h"

namespace iblcheck::truth {

struct QuadratureParams {
    double tolerance = 1e-3; // relative (indicator sum / (value + floor))
    double floor = 0;        // absolute radiance added to the value in the tolerance
    double kappa = 0.5;      // lobe guard: cells on the lobe's core are split until radius ≤ κ·w
    size_t max_splits = 50000;
};

struct ShadeStats {
    long evaluations = 0; // BRDF evaluations
    long splits = 0;
    double error = 0; // Σ indicators (absolute, rgb_size)
    bool budget_hit = false;
};

// Outgoing radiance at shading point s (RGB, added to rgb[]).
void shade(const EnvPyramid& env, const MaterialLobe& lobe, const ShadingPoint& s, const QuadratureParams& p, double rgb[3],
           ShadeStats* stats = nullptr);

} // namespace iblcheck::truth
