// Cubemap storage of the prefiltered chain (option storage, define STORAGE). Filtering happens on what is stored, as on a device: for RGBM that means
// bilinear interpolation of encoded values, one of the format's real artefacts.
#ifndef IBLCHECK_STORAGE_GLSL
#define IBLCHECK_STORAGE_GLSL

#ifndef STORAGE
#error "STORAGE is set from the option table (renderers/option_table.cpp)"
#endif
// RGBM range (Karis, "RGBM color encoding", 2009: linear RGBM with range 6 as in UE3/UE4 captures).
#ifndef RGBM_RANGE
#define RGBM_RANGE 6.0
#endif

#if STORAGE == STORAGE_RGBA32F
#define STORAGE_FORMAT rgba32f
#elif STORAGE == STORAGE_RGBA16F
#define STORAGE_FORMAT rgba16f
#elif STORAGE == STORAGE_RGBM8
#define STORAGE_FORMAT rgba8
#elif STORAGE == STORAGE_R11G11B10
// Stored in an rgba16f image after rounding to the packed format's precision (below), unless the
// host found VK_FORMAT_B10G11R11_UFLOAT_PACK32 usable as a storage image (STORAGE_NATIVE_R11G11B10).
#ifdef STORAGE_NATIVE_R11G11B10
#define STORAGE_FORMAT r11f_g11f_b10f
#else
#define STORAGE_FORMAT rgba16f
#endif
#elif STORAGE == STORAGE_ASTC_HDR || STORAGE == STORAGE_ASTC_LDR_RGBM
// ASTC (renderers/mobile/astc_storage.h): the prefilter pass writes the linear radiance in full
// precision; the host encodes every level with astcenc (RGBM on the host for astc_ldr_rgbm),
// decodes it as the format specifies (to fp16) and uploads the decoded texels as RGBA16F, which
// the shading pass filters and decodes below.
#define STORAGE_FORMAT rgba32f
#endif

// Rounds a non-negative value to an unsigned float with `mbits` mantissa bits and 5 exponent bits
// (the 11- and 10-bit floats of R11G11B10: max 65024 and 64512, no sign, round to nearest).
float quantize_ufloat(float x, int mbits, float max_value) {
    x = clamp(x, 0.0, max_value);
    if (x == 0.0) return 0.0;
    int e;
    frexp(x, e);                                  // x = f·2^e, f in [0.5, 1)
    float step = exp2(float(max(e, -13) - 1 - mbits)); // denormals below 2^-14
    return min(round(x / step) * step, max_value);
}

vec4 encode_storage(vec3 c) {
    c = max(c, vec3(0.0));
#if STORAGE == STORAGE_RGBM8
    float m = clamp(max(max(c.r, c.g), max(c.b, 1e-6)) / RGBM_RANGE, 0.0, 1.0);
    m = ceil(m * 255.0) / 255.0;
    return vec4(clamp(c / (m * RGBM_RANGE), 0.0, 1.0), m);
#elif STORAGE == STORAGE_R11G11B10
    return vec4(quantize_ufloat(c.r, 6, 65024.0), quantize_ufloat(c.g, 6, 65024.0), quantize_ufloat(c.b, 5, 64512.0), 1.0);
#else
    return vec4(c, 1.0);
#endif
}

vec3 decode_storage(vec4 s) {
#if STORAGE == STORAGE_RGBM8 || STORAGE == STORAGE_ASTC_LDR_RGBM
    return s.rgb * s.a * RGBM_RANGE;
#else
    return s.rgb;
#endif
}

#endif
