// The Monte Carlo integrator's sampling functions (monte_carlo.h, "Lighting"), one named function each,
// as pbrt-v4's sampling.h: the shading frame, GGX visible-normal sampling, cosine hemisphere sampling,
// the lobe choice that keeps each lobe's points stratified, and the two MIS weights. Inline: they are the
// inner loop. Tests beside them: mc_sampling_test.cpp.
#pragma once
#include <algorithm>
#include <cmath>

#include "kernel/vec3.h"
#include "renderers/material_model.h"

namespace iblcheck::reference {

// An orthonormal frame (t, b, n) about the unit normal n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited"): local coordinates have n as +z.
struct ShadingFrame {
    Vec3d t, b, n;
    explicit ShadingFrame(Vec3d normal) : n(normal) {
        const double sign = std::copysign(1.0, n.z);
        const double a = -1.0 / (sign + n.z), bb = n.x * n.y * a;
        t = Vec3d{1 + sign * n.x * n.x * a, sign * bb, -sign * n.x};
        b = Vec3d{bb, sign + n.y * n.y * a, -n.y};
    }
    Vec3d to_local(Vec3d w) const { return Vec3d{dot(w, t), dot(w, b), dot(w, n)}; }
    Vec3d to_world(Vec3d l) const { return l.x * t + l.y * b + l.z * n; }
};

// A half-vector h drawn from GGX's distribution of visible normals for the local view direction vl
// (vl.z > 0) and roughness α, from (u0, u1) in [0,1)² (Heitz 2018, "Sampling the GGX Distribution of
// Visible Normals"): pdf(h) = D(h)·G1(v)·max(0, v·h)/(n·v). Always h.z ≥ 0 and v·h ≥ 0.
inline Vec3d sample_ggx_vndf(Vec3d vl, double alpha, double u0, double u1) {
    const Vec3d vh = normalize(Vec3d{alpha * vl.x, alpha * vl.y, vl.z});
    const double lensq = vh.x * vh.x + vh.y * vh.y;
    const Vec3d T1 = lensq > 0 ? (1.0 / std::sqrt(lensq)) * Vec3d{-vh.y, vh.x, 0} : Vec3d{1, 0, 0};
    const Vec3d T2 = cross(vh, T1);
    const double r = std::sqrt(u0), phi = 2 * model::kPi * u1;
    double t1 = r * std::cos(phi), t2 = r * std::sin(phi);
    const double s = 0.5 * (1 + vh.z);
    t2 = (1 - s) * std::sqrt(std::max(0.0, 1 - t1 * t1)) + s * t2;
    const Vec3d nh = t1 * T1 + t2 * T2 + std::sqrt(std::max(0.0, 1 - t1 * t1 - t2 * t2)) * vh;
    return normalize(Vec3d{alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)});
}

// vl mirrored about h: 2(v·h)h − v.
inline Vec3d reflect_about(Vec3d vl, Vec3d h) { return 2 * dot(vl, h) * h + (-1.0) * vl; }

// A local direction drawn ∝ cos θ over the hemisphere (pdf = l.z/π), from (u0, u1) in [0,1)²: the
// polar map r = √u0, φ = 2πu1 (Malley's method).
inline Vec3d sample_cosine_hemisphere(double u0, double u1) {
    const double r = std::sqrt(u0), phi = 2 * model::kPi * u1;
    return Vec3d{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u0))};
}

// The lobe choice of the BRDF strategy: true (specular) when u < p_s, and u rescaled to [0,1) within the
// chosen part, so each lobe gets a stratified sub-pattern of the Sobol points (a separate selection
// number would give each a random subset) and the remapped u is uniform given the choice.
inline bool select_lobe(double p_s, double& u) {
    const bool specular = u < p_s;
    u = specular ? u / p_s : (u - p_s) / (1 - p_s);
    u = std::min(u, 1.0 - 1e-16);
    return specular;
}

// MIS weights of one sample from each of two strategies, the power heuristic (β = 2) or the balance
// heuristic: the weight of a BRDF-strategy sample (pdfs p_brdf of its own strategy, p_env of the other)
// and of an environment-strategy sample. Each is written as the integrator has always evaluated it, so
// the images stay bit for bit; for the same pair of pdfs the two weights sum to 1.
inline double mis_weight_brdf_sample(double p_brdf, double p_env, bool power) {
    return power ? p_brdf / (p_brdf + p_env * (p_env / p_brdf)) : p_brdf / (p_brdf + p_env);
}
inline double mis_weight_env_sample(double p_env, double p_brdf, bool power) {
    return power ? p_env * p_env / (p_env * p_env + p_brdf * p_brdf) : p_env / (p_env + p_brdf);
}

} // namespace iblcheck::reference
