// Branch-free float32 cbrt / log2 / exp2 / pow for FLIP's per-pixel colour and feature maths.
// libm's cbrtf and powf are opaque calls that keep the per-pixel loop scalar; these are plain
// arithmetic the compiler vectorises. Accuracy (relative): cbrt ~2e-7, pow ~5e-7 for the ranges
// FLIP uses (inputs in [0, 1e3], exponents in [0, 1]), far inside the 2e-4 per-pixel agreement
// budget with the reference tool (tests/test_metrics_flip.cpp measures it).
#pragma once
#include <bit>
#include <cstdint>

// Always inlined: the FLIP kernels are compiled once per instruction set (flip/kernels.h), and an
// out-of-line copy of a helper compiled for AVX2 could be the one the linker keeps for every caller.
#define IBLCHECK_FLIP_INLINE inline __attribute__((always_inline))

namespace iblcheck::flip {

// Cube root for x >= 0: exponent/3 bit estimate, then Newton y <- y - (y^3 - x) / (3 y^2).
IBLCHECK_FLIP_INLINE float fast_cbrt(float x) {
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    float y = std::bit_cast<float>(bits / 3u + 709921077u); // ~6% initial error
    y = y - (y * y * y - x) / (3.0f * y * y);
    y = y - (y * y * y - x) / (3.0f * y * y);
    y = y - (y * y * y - x) / (3.0f * y * y);
    y = y - (y * y * y - x) / (3.0f * y * y);
    return x == 0.0f ? 0.0f : y;
}

// log2 for x > 0 (normal floats): x = m 2^e, m in [sqrt(1/2), sqrt(2)),
// ln m = 2 atanh(t), t = (m - 1) / (m + 1), |t| <= 0.1716, series to t^9.
IBLCHECK_FLIP_INLINE float fast_log2(float x) {
    const int32_t bits = std::bit_cast<int32_t>(x);
    // Re-bias so the mantissa lands in [sqrt(1/2), sqrt(2)).
    const int32_t off = bits - 0x3f3504f3;
    const int32_t e = off >> 23;
    const float m = std::bit_cast<float>(bits - (e << 23));
    const float t = (m - 1.0f) / (m + 1.0f);
    const float t2 = t * t;
    const float s = t * (2.0f + t2 * (2.0f / 3.0f + t2 * (2.0f / 5.0f + t2 * (2.0f / 7.0f + t2 * (2.0f / 9.0f)))));
    return float(e) + s * 1.44269504088896341f;
}

// 2^y for y in about [-126, 127]: 2^round(y) by bits, 2^f (|f| <= 0.5) by Taylor to degree 7.
IBLCHECK_FLIP_INLINE float fast_exp2(float y) {
    y = y < -126.0f ? -126.0f : (y > 127.0f ? 127.0f : y);
    const float n = float(int32_t(y + (y >= 0.0f ? 0.5f : -0.5f)));
    const float f = (y - n) * 0.693147180559945309f;
    const float p =
        1.0f +
        f * (1.0f + f * (0.5f + f * (1.0f / 6.0f +
                                     f * (1.0f / 24.0f + f * (1.0f / 120.0f + f * (1.0f / 720.0f + f * (1.0f / 5040.0f)))))));
    const float scale = std::bit_cast<float>((int32_t(n) + 127) << 23);
    return p * scale;
}

// x^p for x >= 0, p >= 0, with pow's conventions 0^0 = 1 and 0^p = 0 (p > 0).
IBLCHECK_FLIP_INLINE float fast_pow(float x, float p) {
    const float tiny = x > 1e-30f ? 0.0f : 1.0f;        // arithmetic masks keep the loop
    const float r = fast_exp2(p * fast_log2(x + tiny)); // branch-free (vectorises under AVX2)
    const float zero_value = p == 0.0f ? 1.0f : 0.0f;
    return r * (1.0f - tiny) + zero_value * tiny;
}

} // namespace iblcheck::flip
