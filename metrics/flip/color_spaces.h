// Colour-space conversions used by FLIP (FLIP paper, Sec. 4.1): sRGB <-> linear RGB, linear
// RGB <-> XYZ (D65), XYZ <-> YCxCz (opponent space of Zhang & Wandell's S-CIELAB, where the CSF
// filtering happens) and XYZ -> CIELab, plus the Hunt adjustment and the HyAB distance.
// Pure scalar float32 functions, written in the same operation order as the reference tool so
// results round the same way.
#pragma once
#include <cmath>

#include "metrics/flip/fast_math.h"
#include "metrics/flip/flip_constants.h"

namespace iblcheck::flip {

// IEC 61966-2-1 sRGB EOTF / OETF (piecewise; linear toe below 0.04045 / 0.0031308).
inline float srgb_to_linear(float c) {
    if (c <= 0.04045f) return c / 12.92f;
    return std::pow((c + 0.055f) / 1.055f, 2.4f);
}
inline float linear_to_srgb(float c) {
    if (c <= 0.0031308f) return c * 12.92f;
    return 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// Linear sRGB primaries -> CIE XYZ, D65, exact rational coefficients (the tool's matrix).
IBLCHECK_FLIP_INLINE void linear_rgb_to_xyz(float r, float g, float b, float& x, float& y, float& z) {
    constexpr float a11 = 10135552.0f / 24577794.0f, a12 = 8788810.0f / 24577794.0f, a13 = 4435075.0f / 24577794.0f;
    constexpr float a21 = 2613072.0f / 12288897.0f, a22 = 8788810.0f / 12288897.0f, a23 = 887015.0f / 12288897.0f;
    constexpr float a31 = 1425312.0f / 73733382.0f, a32 = 8788810.0f / 73733382.0f, a33 = 70074185.0f / 73733382.0f;
    x = a11 * r + a12 * g + a13 * b;
    y = a21 * r + a22 * g + a23 * b;
    z = a31 * r + a32 * g + a33 * b;
}

IBLCHECK_FLIP_INLINE void xyz_to_linear_rgb(float x, float y, float z, float& r, float& g, float& b) {
    r = 3.241003275f * x + -1.537398934f * y + -0.498615861f * z;
    g = -0.969224334f * x + 1.875930071f * y + 0.041554224f * z;
    b = 0.055639423f * x + -0.204011202f * y + 1.057148933f * z;
}

// YCxCz: the linear (no cube root) variant of CIELab (FLIP paper, Sec. 4.1).
IBLCHECK_FLIP_INLINE void xyz_to_ycxcz(float x, float y, float z, float& Y, float& Cx, float& Cz) {
    x *= kInvD65[0];
    y *= kInvD65[1];
    z *= kInvD65[2];
    Y = 116.0f * y - 16.0f;
    Cx = 500.0f * (x - y);
    Cz = 200.0f * (y - z);
}
IBLCHECK_FLIP_INLINE void ycxcz_to_xyz(float Y, float Cx, float Cz, float& x, float& y, float& z) {
    const float yy = (Y + 16.0f) / 116.0f;
    const float cx = Cx / 500.0f;
    const float cz = Cz / 200.0f;
    x = (yy + cx) * kD65[0];
    y = yy * kD65[1];
    z = (yy - cz) * kD65[2];
}

// CIELab's nonlinearity f(t) (cube root above (6/29)^3, linear segment below).
inline float lab_f(float t) {
    constexpr float delta = 6.0f / 29.0f;
    constexpr float delta_cube = delta * delta * delta;
    constexpr float factor = 1.0f / (3.0f * delta * delta);
    constexpr float term = 4.0f / 29.0f;
    return t > delta_cube ? std::cbrt(t) : factor * t + term;
}
inline void xyz_to_lab(float x, float y, float z, float& L, float& a, float& b) {
    const float fx = lab_f(x * kInvD65[0]);
    const float fy = lab_f(y * kInvD65[1]);
    const float fz = lab_f(z * kInvD65[2]);
    L = 116.0f * fy - 16.0f;
    a = 500.0f * (fx - fy);
    b = 200.0f * (fy - fz);
}

// Hunt effect (FLIP paper, Eq. 4): chroma scales with luminance, so dark colours differ less.
IBLCHECK_FLIP_INLINE float hunt(float L, float chroma) { return 0.01f * L * chroma; }

// HyAB distance (FLIP paper, Eq. 5): city-block on L, Euclidean on (a, b).
inline float hyab(float L1, float a1, float b1, float L2, float a2, float b2) {
    const float da = a1 - a2, db = b1 - b2;
    return std::fabs(L1 - L2) + std::sqrt(da * da + db * db);
}

// cmax: the largest Hunt-adjusted HyAB distance in the sRGB gamut, between pure green and pure
// blue (FLIP paper, Sec. 4.1), raised to qc.
inline float max_color_distance() {
    float x, y, z, Lg, ag, bg, Lb, ab, bb;
    linear_rgb_to_xyz(0.0f, 1.0f, 0.0f, x, y, z);
    xyz_to_lab(x, y, z, Lg, ag, bg);
    linear_rgb_to_xyz(0.0f, 0.0f, 1.0f, x, y, z);
    xyz_to_lab(x, y, z, Lb, ab, bb);
    return std::pow(hyab(Lg, hunt(Lg, ag), hunt(Lg, bg), Lb, hunt(Lb, ab), hunt(Lb, bb)), kQc);
}

} // namespace iblcheck::flip
