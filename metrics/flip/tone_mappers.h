// Tone mappers and the automatic exposure range of HDR-FLIP (HDR-FLIP paper, Sec. 4).
// All three are rational functions (c^2 k0 + c k1 + k2) / (c^2 k3 + c k4 + k5) per channel,
// except Reinhard, which the tool applies on luminance: c / (1 + Y).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kernel/errors.h"
#include "metrics/flip/fast_math.h"
#include "metrics/flip/flip_constants.h"

namespace iblcheck::flip {

enum class ToneMapper { reinhard = 0, aces = 1, hable = 2 };

// Coefficients k0..k5 of the rational curve.
// ACES: Narkowicz 2016, "ACES Filmic Tone Mapping Curve", (x(2.51x + 0.03)) / (x(2.43x + 0.59)
// + 0.14), with the 0.6 input scale he gives for the original ACES curve folded in (x -> 0.6x).
// Hable: John Hable's "Uncharted 2" filmic curve, as the FLIP tool parameterises it.
inline constexpr float kToneCoefficients[3][6] = {
    {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f},                                                // Reinhard
    {0.6f * 0.6f * 2.51f, 0.6f * 0.03f, 0.0f, 0.6f * 0.6f * 2.43f, 0.6f * 0.59f, 0.14f}, // ACES
    {0.231683f, 0.013791f, 0.0f, 0.18f, 0.3f, 0.018f},                                   // Hable
};

inline ToneMapper parse_tone_mapper(const std::string& name) {
    if (name == "aces") return ToneMapper::aces;
    if (name == "hable") return ToneMapper::hable;
    if (name == "reinhard") return ToneMapper::reinhard;
    throw UsageError("unknown tone mapper '" + name + "' (expected aces, hable or reinhard)");
}
inline const char* tone_mapper_name(ToneMapper tm) {
    switch (tm) {
    case ToneMapper::reinhard: return "reinhard";
    case ToneMapper::hable: return "hable";
    default: return "aces";
    }
}

// Inputs above this are computed as this. ACES and Hable approach k0/k3 > 1 from below, so they
// pass 1 (every caller's clamp) long before it (ACES at 12.1, Hable at 5.6), and c * c overflows
// float from 1.8e19: a pixel at 1e20 used to give inf/inf = NaN, which FLIP's running max over
// exposures and SSIM then lost (an all-zero error map, SSIM null). Saturating changes nothing
// below it and gives the exact clamped value above it; a NaN stays a NaN.
inline constexpr float kToneMapSaturation = 1e18f;

// One channel of the rational curve (not Reinhard).
IBLCHECK_FLIP_INLINE float tone_map_channel(float c, const float* k) {
    c = c > kToneMapSaturation ? kToneMapSaturation : c;
    return ((c * c) * k[0] + c * k[1] + k[2]) / ((c * c) * k[3] + c * k[4] + k[5]);
}

// Reinhard's c / (1 + Y) holds at any finite c below 1e38; an exposed value that overflowed to inf
// (inf * 0 = NaN), or one where Y would round to inf, is computed as 1e38 (the same clamped output
// to within 1e-37).
IBLCHECK_FLIP_INLINE float reinhard_input(float c) { return c > 1e38f ? 1e38f : c; }

// Tone-maps one linear RGB pixel in place.
IBLCHECK_FLIP_INLINE void tone_map(ToneMapper tm, float& r, float& g, float& b) {
    if (tm == ToneMapper::reinhard) {
        r = reinhard_input(r);
        g = reinhard_input(g);
        b = reinhard_input(b);
        const float lum = 0.2126f * r + 0.7152f * g + 0.0722f * b;
        const float factor = 1.0f / (1.0f + lum);
        r *= factor;
        g *= factor;
        b *= factor;
        return;
    }
    const float* k = kToneCoefficients[int(tm)];
    r = tone_map_channel(r, k);
    g = tone_map_channel(g, k);
    b = tone_map_channel(b, k);
}

// Automatic exposure range (HDR-FLIP paper, Sec. 4.2): solve tm(x) = 0.85 for x, then
// start = log2(x / Ymax) (the brightest reference pixel just reaches 0.85 at the first exposure)
// and stop = log2(x / Ymedian) (the median luminance reaches it at the last). The median is the
// element at index n/2 of the sorted luminances, as in the tool (no averaging for even n).
struct ExposureRange {
    float start = 0.0f, stop = 0.0f;
};

inline ExposureRange auto_exposure_range(ToneMapper tm, std::vector<float> luminances) {
    const float* k = kToneCoefficients[int(tm)];
    const float t = kHdrTargetToneMapped;
    const float a = k[0] - t * k[3], b = k[1] - t * k[4], c = k[2] - t * k[5];
    float x_max;
    if (a == 0.0f) {
        x_max = -c / b;
    } else {
        const float d1 = -0.5f * (b / a);
        const float d2 = std::sqrt((d1 * d1) - (c / a));
        x_max = d1 + d2;
    }
    float y_max = -1e30f;
    for (float l : luminances) y_max = std::max(y_max, l);
    const size_t mid = luminances.size() / 2;
    std::nth_element(luminances.begin(), luminances.begin() + mid, luminances.end());
    const float y_median = luminances[mid];
    return {std::log2(x_max / y_max), std::log2(x_max / y_median)};
}

// Number of exposures when not given: one per stop, at least two (the tool's rule).
inline int auto_num_exposures(float start, float stop) { return int(std::max(2.0f, std::ceil(stop - start))); }

} // namespace iblcheck::flip
