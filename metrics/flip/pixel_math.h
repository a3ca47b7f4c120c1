// FLIP's per-pixel colour and feature maths after filtering (FLIP paper, Eqs. 4-10), written once
// and used by every kernel variant (flip/kernels.h), so the scalar reference and the vectorised
// loops do the same operations in the same order. Only correctly rounded IEEE operations (builtins,
// no library calls), always inlined (see IBLCHECK_FLIP_INLINE).
#pragma once
#include "metrics/flip/color_spaces.h"
#include "metrics/flip/fast_math.h"
#include "metrics/flip/flip_constants.h"
#include "metrics/flip/tone_mappers.h"

namespace iblcheck::flip::pixel {

// std::max(v, lo) and std::min(v, hi), spelled out (same results, NaN included).
IBLCHECK_FLIP_INLINE float max_of(float v, float lo) { return v < lo ? lo : v; }
IBLCHECK_FLIP_INLINE float min_of(float v, float hi) { return hi < v ? hi : v; }

// std::min(std::max(v, 0), 1).
IBLCHECK_FLIP_INLINE float clamp01(float v) { return min_of(max_of(v, 0.0f), 1.0f); }

// An 8-bit sRGB code k/255 -> linear through the 256-entry table (code[k] = k/255, linear[k] its
// linear value); -1 when v is not exactly such a code (the caller computes those with the formula).
IBLCHECK_FLIP_INLINE float srgb_code_to_linear(float v, const float* code, const float* linear) {
    float s = v * 255.0f + 0.5f;
    s = s >= 0.0f && s < 256.0f ? s : 0.0f; // NaN too: index 0, then a miss
    const int k = int(s);
    const float c = code[k], l = linear[k]; // both loads unconditional: the loop vectorises (gathers)
    return c == v ? clamp01(l) : -1.0f;
}

// HDR-FLIP's input for one exposure: radiance * 2^exposure, tone mapped, clamped to [0,1].
IBLCHECK_FLIP_INLINE void expose_tone_map(const float* p, float m, ToneMapper tm, float& R, float& G, float& B) {
    float cr = p[0] * m, cg = p[1] * m, cb = p[2] * m;
    tone_map(tm, cr, cg, cb);
    R = clamp01(cr);
    G = clamp01(cg);
    B = clamp01(cb);
}

// Linear RGB -> YCxCz and the feature channel Y normalised to [0,1] (FLIP paper, Sec. 4.2).
IBLCHECK_FLIP_INLINE void rgb_to_ycxcz(float r, float g, float b, float& Y, float& Cx, float& Cz, float& Yn) {
    float X, Yy, Z;
    linear_rgb_to_xyz(r, g, b, X, Yy, Z);
    xyz_to_ycxcz(X, Yy, Z, Y, Cx, Cz);
    constexpr float one_over_116 = 1.0f / 116.0f, sixteen_over_116 = 16.0f / 116.0f;
    Yn = Y * one_over_116 + sixteen_over_116;
}

// CIELab's f(t) with the fast cube root (cube root above (6/29)^3, linear segment below).
IBLCHECK_FLIP_INLINE float lab_f(float t) {
    constexpr float delta = 6.0f / 29.0f;
    constexpr float delta_cube = delta * delta * delta;
    constexpr float factor = 1.0f / (3.0f * delta * delta);
    constexpr float term = 4.0f / 29.0f;
    const float c = fast_cbrt(t > delta_cube ? t : delta_cube);
    return t > delta_cube ? c : factor * t + term;
}

// Filtered YCxCz may leave the gamut: clamp in linear RGB, then CIELab with Hunt (Eq. 4).
IBLCHECK_FLIP_INLINE void to_hunt_lab(float Y, float Cx, float Cz, float& L, float& a, float& b) {
    float X, Yy, Z, r, g, bl;
    ycxcz_to_xyz(Y, Cx, Cz, X, Yy, Z);
    xyz_to_linear_rgb(X, Yy, Z, r, g, bl);
    r = min_of(max_of(r, 0.0f), 1.0f);
    g = min_of(max_of(g, 0.0f), 1.0f);
    bl = min_of(max_of(bl, 0.0f), 1.0f);
    linear_rgb_to_xyz(r, g, bl, X, Yy, Z);
    const float fx = lab_f(X * kInvD65[0]);
    const float fy = lab_f(Yy * kInvD65[1]);
    const float fz = lab_f(Z * kInvD65[2]);
    L = 116.0f * fy - 16.0f;
    a = hunt(L, 500.0f * (fx - fy));
    b = hunt(L, 200.0f * (fy - fz));
}

// One pixel's FLIP from its 16 filtered values v[img * 8 + i] (i: Y, Cx, Cz1, Cz2, dx, ddx, dy, ddy).
IBLCHECK_FLIP_INLINE float flip_value(const float* v, float cmax, float pccmax) {
    const float norm = 1.0f / __builtin_sqrtf(2.0f);
    // Colour difference (FLIP paper, Eqs. 4-7).
    float Lr, ar, br, Lt, at, bt;
    to_hunt_lab(v[0], v[1], v[2] + v[3], Lr, ar, br);
    to_hunt_lab(v[8], v[9], v[10] + v[11], Lt, at, bt);
    const float da = ar - at, db = br - bt;
    const float dist = __builtin_fabsf(Lr - Lt) + __builtin_sqrtf(da * da + db * db);
    const float c = fast_pow(dist, kQc);
    // Eq. 7: [0, pc*cmax] -> [0, pt], [pc*cmax, cmax] -> [pt, 1].
    const float cdiff = c < pccmax ? c * (kPt / pccmax) : kPt + ((c - pccmax) / (cmax - pccmax)) * (1.0f - kPt);
    // Feature difference (FLIP paper, Eq. 9).
    const float dxr = v[4], ddxr = v[5], dyr = v[6], ddyr = v[7];
    const float dxt = v[12], ddxt = v[13], dyt = v[14], ddyt = v[15];
    const float edge = __builtin_fabsf(__builtin_sqrtf(dxr * dxr + dyr * dyr) - __builtin_sqrtf(dxt * dxt + dyt * dyt));
    const float point = __builtin_fabsf(__builtin_sqrtf(ddxr * ddxr + ddyr * ddyr) - __builtin_sqrtf(ddxt * ddxt + ddyt * ddyt));
    const float fdiff = __builtin_sqrtf(norm * (edge > point ? edge : point)); // ^qf, qf = 0.5
    // Eq. 10: features sharpen the colour error towards 1.
    return fast_pow(cdiff, 1.0f - fdiff);
}

} // namespace iblcheck::flip::pixel
