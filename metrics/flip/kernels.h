// The hot loops of the FLIP engine (metrics/flip.cpp), compiled three times:
//   scalar  one pixel at a time, plain loops, auto-vectorisation off: the reference,
//   sse2    8-pixel GCC vector types on baseline x86-64 (two SSE registers each),
//   avx2    the same source compiled with -mavx2 (one AVX register each).
// Every variant does the same IEEE float operations per pixel in the same order: no FMA (it rounds
// once where mul + add rounds twice, and not every CPU has it: -ffp-contract=off), no reassociation
// (no -ffast-math), only correctly rounded +, -, *, /, sqrt, min/max and selects. So a FLIP value
// does not depend on the CPU's SIMD width or FMA (issue 15: the same verdict on every CI machine);
// tests/test_flip_kernels.cpp checks the variants bit for bit.
#pragma once
#include <string>
#include <vector>

#include "metrics/flip/tone_mappers.h"

namespace iblcheck::flip {

struct Kernels {
    const char* name;
    // out[f][x] = sum over k ascending of taps[f][k] * src[k][x], for nf filters (1..3) sharing the
    // same sources; the first term is 0 + taps[f][0] * src[0][x] (the reference tool's tap order).
    void (*fir)(const float* const* src, const float* const* taps, int nf, int ntaps, int n, float* const* out);
    // Interleaved RGB of an 8-bit sRGB image (values k/255) -> linear planes, clamped to [0,1],
    // through the 256-entry tables; a value that is not k/255 gives -1 (the caller applies the formula).
    void (*srgb_to_linear)(const float* rgb, int n, const float* code, const float* linear, float* r, float* g, float* b);
    // Interleaved linear RGB -> planes of HDR-FLIP's input for one exposure: * m, tone mapped, clamped.
    void (*expose_tone_map)(const float* rgb, int n, float m, ToneMapper tm, float* r, float* g, float* b);
    // Linear RGB -> YCxCz (Y, Cx, Cz) and the feature channel Yn = Y / 116 + 16 / 116.
    void (*rgb_to_ycxcz)(const float* r, const float* g, const float* b, int n, float* y, float* cx, float* cz, float* yn);
    // Per-pixel FLIP from the 16 vertically filtered planes q[img * 8 + i] (i: Y, Cx, Cz1, Cz2, dx, ddx,
    // dy, ddy); cmax and pc * cmax of the colour pipeline. With max_merge, out = max(out, FLIP).
    void (*flip_pixels)(const float* const* q, int n, float cmax, float pccmax, float* out, bool max_merge);
};

const Kernels& scalar_kernels();
const Kernels& sse2_kernels();
const Kernels& avx2_kernels(); // only on a CPU with AVX2 (cpu_has_avx2())

bool cpu_has_avx2();
// The fastest variant this CPU runs: avx2 or sse2. IBLCHECK_FLIP_KERNELS=scalar|sse2|avx2 picks one
// (benchmarks, tests); an unknown or unsupported name is an EnvironmentError.
const Kernels& default_kernels();
// The variant called `name`; throws UsageError/EnvironmentError for an unknown/unsupported name.
const Kernels& kernels_named(const std::string& name);
// The variants this CPU can run, scalar first.
std::vector<const Kernels*> available_kernels();

} // namespace iblcheck::flip
