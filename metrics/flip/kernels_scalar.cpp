// The scalar reference of the FLIP kernels (flip/kernels.h): one pixel at a time, in the plainest
// form, compiled with auto-vectorisation off. The vector variants must match it bit for bit.
#include "metrics/flip/kernels.h"
#include "metrics/flip/pixel_math.h"

namespace iblcheck::flip {

namespace {

void fir(const float* const* src, const float* const* taps, int nf, int ntaps, int n, float* const* out) {
    for (int f = 0; f < nf; ++f)
        for (int x = 0; x < n; ++x) {
            float a = 0.0f + taps[f][0] * src[0][x];
            for (int k = 1; k < ntaps; ++k) a += taps[f][k] * src[k][x];
            out[f][x] = a;
        }
}

void srgb_to_linear(const float* __restrict rgb, int n, const float* __restrict code, const float* __restrict linear,
                    float* __restrict r, float* __restrict g, float* __restrict b) {
    for (int x = 0; x < n; ++x) r[x] = pixel::srgb_code_to_linear(rgb[3 * x], code, linear);
    for (int x = 0; x < n; ++x) g[x] = pixel::srgb_code_to_linear(rgb[3 * x + 1], code, linear);
    for (int x = 0; x < n; ++x) b[x] = pixel::srgb_code_to_linear(rgb[3 * x + 2], code, linear);
}

void expose_tone_map(const float* __restrict rgb, int n, float m, ToneMapper tm, float* __restrict r, float* __restrict g,
                     float* __restrict b) {
    // One loop per tone mapper, so the choice is not made per pixel.
    switch (tm) {
    case ToneMapper::reinhard:
        for (int x = 0; x < n; ++x) pixel::expose_tone_map(rgb + 3 * x, m, ToneMapper::reinhard, r[x], g[x], b[x]);
        break;
    case ToneMapper::hable:
        for (int x = 0; x < n; ++x) pixel::expose_tone_map(rgb + 3 * x, m, ToneMapper::hable, r[x], g[x], b[x]);
        break;
    default:
        for (int x = 0; x < n; ++x) pixel::expose_tone_map(rgb + 3 * x, m, ToneMapper::aces, r[x], g[x], b[x]);
    }
}

void rgb_to_ycxcz(const float* r, const float* g, const float* b, int n, float* y, float* cx, float* cz, float* yn) {
    for (int x = 0; x < n; ++x) pixel::rgb_to_ycxcz(r[x], g[x], b[x], y[x], cx[x], cz[x], yn[x]);
}

void flip_pixels(const float* const* q, int n, float cmax, float pccmax, float* out, bool max_merge) {
    float v[16];
    for (int x = 0; x < n; ++x) {
        for (int i = 0; i < 16; ++i) v[i] = q[i][x];
        const float e = pixel::flip_value(v, cmax, pccmax);
        out[x] = max_merge ? (e > out[x] ? e : out[x]) : e;
    }
}

} // namespace

const Kernels& scalar_kernels() {
    static const Kernels k{"scalar", fir, srgb_to_linear, expose_tone_map, rgb_to_ycxcz, flip_pixels};
    return k;
}

} // namespace iblcheck::flip
