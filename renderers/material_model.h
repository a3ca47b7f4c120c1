// The material model, written down once (issue 4). Every method — the mobile pipeline's GLSL
// (renderers/shaders/brdf.glsl), the sampled peer and the CPU reference integrator
// (renderers/reference/) — evaluates exactly this; the GLSL mirrors these equations and cites this file.
//
// Metallic-roughness material: base colour c, metallic m, perceptual roughness r, α = r².
//
//   f(l, v) = (1 − m) · c / π  +  D(h) · V(l, v) · F(v·h)                    (Lambert + microfacet)
//
//   D(h)  = α² / (π ((n·h)² (α² − 1) + 1)²)                 GGX / Trowbridge–Reitz (Walter et al. 2007, eq. 33)
//   V     = 0.5 / (n·l √((n·v)² (1 − α²) + α²) + n·v √((n·l)² (1 − α²) + α²))
//           height-correlated Smith G2 / (4 n·l n·v) (Heitz 2014, "Understanding the Masking-Shadowing
//           Function", eq. 99; the form of Filament's V_SmithGGXCorrelated)
//   F     = F0 + (1 − F0)(1 − v·h)⁵                          Schlick 1994
//   F0    = mix(0.04, c, m)
//
// Note the diffuse term carries no (1 − F) factor: the model is the plain sum, as in the issue.
// Reference values (DEVELOPERS.md): GGX + height-correlated Smith with F0 = 1 in a white furnace at
// normal incidence has directional albedo E = 0.91581 at r = 0.5 and 1 − ln 2 = 0.30685 at r = 1.
#pragma once
#include <algorithm>
#include <cmath>

namespace iblcheck::model {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDielectricF0 = 0.04;

inline double alpha_from_roughness(double r) { return r * r; }

// GGX normal distribution D(h), Walter et al. 2007 eq. 33.
inline double d_ggx(double n_dot_h, double alpha) {
    double a2 = alpha * alpha;
    double t = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (kPi * t * t);
}

// Height-correlated Smith visibility V = G2 / (4 n·l n·v), Heitz 2014 eq. 99.
inline double v_smith_ggx_correlated(double n_dot_v, double n_dot_l, double alpha) {
    double a2 = alpha * alpha;
    double gv = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    double gl = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / (gv + gl);
}

// Schlick's Fresnel approximation, per channel.
inline double f_schlick(double f0, double v_dot_h) {
    double x = 1.0 - std::clamp(v_dot_h, 0.0, 1.0);
    double x2 = x * x;
    return f0 + (1.0 - f0) * x2 * x2 * x;
}

inline double f0_from(double base_color, double metallic) { return kDielectricF0 * (1.0 - metallic) + base_color * metallic; }

} // namespace iblcheck::model
