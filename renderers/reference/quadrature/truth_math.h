// Small vector type and the BRDF in the form the quadrature truth evaluates it: f(l, v)·(n·l)⁺ per
// channel for one material and one shading point, exactly material_model.h's equations.
#pragma once
#include <algorithm>
#include <cmath>

#include "kernel/vec3.h"
#include "renderers/material_model.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::truth {

inline constexpr double kPi = model::kPi;

using V3 = Vec3d; // kernel/vec3.h, with its operations

// Mean of the absolute channel values: the scalar size of an RGB error or value.
inline double rgb_size(const double c[3]) { return (std::fabs(c[0]) + std::fabs(c[1]) + std::fabs(c[2])) / 3; }

// Which lobes of the model to evaluate (option lobes = all|diffuse|specular, as the Monte Carlo integrator).
enum class Lobes { all, diffuse, specular };

// The split-sum rungs of `iblcheck explain` (option split_sum, split_sum.h): off is the truth; exact
// shades every node as P(R, α)·(F0·A + B) + the exact diffuse, with the exact DFG (A, B);
// env_brdf_approx the same with Karis/Lazarov's EnvBRDFApprox for (A, B).
enum class SplitSum { off, exact, env_brdf_approx };

// One sphere's material constants. α < kMirrorAlpha (roughness < 0.01, in practice r = 0) makes the
// specular lobe the delta F(n·v)·L(reflect(v)), as in the Monte Carlo integrator.
inline constexpr double kMirrorAlpha = 1e-4;
struct MaterialLobe {
    double alpha = 0, a2 = 0;
    double f0[3] = {0, 0, 0};
    double kd[3] = {0, 0, 0}; // (1 − m)·c/π
    bool diffuse = false, specular = false, mirror = false;
    SplitSum split_sum = SplitSum::off;
    // The prefilter lobe of the split sum (split_sum.h): the specular term is D(h)·(n·l)·inv_norm per
    // channel, no V, no F (Karis's prefilter weighting, evaluated at n = v = R).
    bool prefilter = false;
    double inv_norm = 0;
    bool glossy() const { return specular && !mirror; } // a continuous specular lobe to integrate
};
inline MaterialLobe material_lobe(const Material& m, Lobes lobes) {
    MaterialLobe L;
    L.alpha = model::alpha_from_roughness(m.roughness);
    L.a2 = L.alpha * L.alpha;
    const double c[3] = {m.base_color.x, m.base_color.y, m.base_color.z};
    L.diffuse = lobes != Lobes::specular && m.metallic < 1;
    L.specular = lobes != Lobes::diffuse;
    L.mirror = L.alpha < kMirrorAlpha;
    for (int i = 0; i < 3; ++i) {
        L.f0[i] = model::f0_from(c[i], m.metallic);
        L.kd[i] = L.diffuse ? (1 - m.metallic) * c[i] / kPi : 0.0;
    }
    return L;
}

// A shading point: normal n, direction to the viewer v. n·v is clamped to ≥ 1e-5 by tilting v toward
// n inside their plane (the Monte Carlo integrator's rule; only the last sliver of a silhouette, or a
// bump normal turned away from the viewer, is affected).
inline constexpr double kMinNdotV = 1e-5;
struct ShadingPoint {
    V3 n, v;
    double nv = 1, gv = 1; // n·v and √((n·v)²(1 − α²) + α²) (material_model.h's V)
};
inline ShadingPoint shading_point(V3 n, V3 v, const MaterialLobe& L) {
    ShadingPoint s;
    s.n = n;
    double nv = dot(n, v);
    if (nv < kMinNdotV) {
        V3 t = v - nv * n;
        double tl = std::sqrt(dot(t, t));
        V3 tn = tl > 1e-300 ? (1.0 / tl) * t
                            : (std::fabs(n.x) < 0.9 ? normalize(V3{1, 0, 0} - n.x * n) : normalize(V3{0, 1, 0} - n.y * n));
        v = std::sqrt(1 - kMinNdotV * kMinNdotV) * tn + kMinNdotV * n;
        nv = kMinNdotV;
    }
    s.v = v;
    s.nv = nv;
    s.gv = std::sqrt(nv * nv * (1 - L.a2) + L.a2);
    return s;
}

// f(l, v)·(n·l)⁺ per channel (l unit, world): Lambert + GGX·V_SmithGGXCorrelated·Schlick, the
// continuous specular lobe only when L.glossy() (a mirror's delta is handled by the caller). The
// specular term is multiplied by spec_weight (the near/far split of a narrow lobe, lobe_quadrature.h),
// the diffuse term by diffuse_weight.
inline void fcos(const MaterialLobe& L, const ShadingPoint& s, V3 l, double out[3], double spec_weight = 1,
                 double diffuse_weight = 1) {
    const double nl = dot(s.n, l);
    if (nl <= 0) {
        out[0] = out[1] = out[2] = 0;
        return;
    }
    for (int i = 0; i < 3; ++i) out[i] = diffuse_weight * L.kd[i] * nl;
    if (!L.glossy() || spec_weight == 0) return;
    V3 h = l + s.v;
    const double hl2 = dot(h, h);
    if (hl2 <= 1e-300) return;
    const double inv = 1.0 / std::sqrt(hl2);
    const double nh = dot(s.n, h) * inv, vh = dot(s.v, h) * inv;
    const double t = nh * nh * (L.a2 - 1) + 1;
    const double d = L.a2 / (kPi * t * t);
    if (L.prefilter) {
        for (int i = 0; i < 3; ++i) out[i] += spec_weight * d * nl * L.inv_norm;
        return;
    }
    const double vis = 0.5 / (nl * s.gv + s.nv * std::sqrt(nl * nl * (1 - L.a2) + L.a2));
    const double x = 1 - std::clamp(vh, 0.0, 1.0), x5 = x * x * x * x * x;
    const double dvn = spec_weight * d * vis * nl;
    for (int i = 0; i < 3; ++i) out[i] += dvn * (L.f0[i] + (1 - L.f0[i]) * x5);
}

} // namespace iblcheck::truth
