// The material model of renderers/material_model.h, in GLSL (same equations, same references).
#ifndef IBLCHECK_BRDF_GLSL
#define IBLCHECK_BRDF_GLSL
#include "common.glsl"

// GGX / Trowbridge–Reitz D(h), Walter et al. 2007 eq. 33.
float d_ggx(float n_dot_h, float alpha) {
    float a2 = alpha * alpha;
    float t = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * t * t);
}

// Height-correlated Smith visibility V = G2 / (4 n·l n·v), Heitz 2014 eq. 99.
float v_smith_ggx_correlated(float n_dot_v, float n_dot_l, float alpha) {
    float a2 = alpha * alpha;
    float gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    float gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / (gv + gl);
}

// Schlick 1994.
vec3 f_schlick(vec3 f0, float v_dot_h) {
    float x = 1.0 - clamp(v_dot_h, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

// Samples a half vector with pdf D(h)·(n·h) (Karis 2013, "Real Shading in UE4", p. 4), in the frame
// around n. pdf of the reflected l is D(h)(n·h) / (4 v·h).
vec3 importance_sample_ggx(vec2 xi, float alpha, vec3 n) {
    float phi = 2.0 * PI * xi.x;
    float cos_theta = sqrt((1.0 - xi.y) / (1.0 + (alpha * alpha - 1.0) * xi.y));
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    vec3 h = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
    vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 tx = normalize(cross(up, n));
    vec3 ty = cross(n, tx);
    return tx * h.x + ty * h.y + n * h.z;
}

#endif
