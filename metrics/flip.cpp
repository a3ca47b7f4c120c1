// FLIP evaluation engine. The arithmetic of each pixel follows the reference tool (float32, same
// operation order, taps summed from -r to +r); the structure is ours: two passes per LDR
// evaluation over planar row buffers,
//   H pass: input row -> linear RGB -> YCxCz -> 7 horizontally filtered planes per image
//           (4 CSF planes: Y, Cx, Cz part 1, Cz part 2; 3 feature planes: G', G'', G on Y),
//   V pass: vertical filtering of those planes in x-tiles, then colour error, feature error and
//           the final FLIP value per pixel (and the running max over exposures for HDR).
// Tap loops run with the tap index outermost and x innermost, so each pixel still accumulates its
// taps in order -r..r (same rounding as the tool) while the compiler vectorises across x.
#include "metrics/flip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "harness/common/errors.h"
#include "metrics/flip/color_spaces.h"
#include "metrics/flip/csf_filters.h"
#include "metrics/flip/fast_math.h"
#include "metrics/flip/feature_detection.h"
#include "metrics/flip/magma_table.h"
#include "metrics/flip/parallel.h"
#include "metrics/flip/pooling.h"

namespace iblcheck {
namespace {

using namespace flip;

// Plane indices of the H pass, per image.
enum Plane { kPY = 0, kPCx, kPCz1, kPCz2, kPDx, kPDdx, kPG, kNumPlanes };

// 8-bit sRGB -> linear lookup: PNG inputs hold exactly k/255, for which the table equals the
// tool's per-pixel powf. Any other value falls back to the formula.
struct SrgbLut {
    std::array<float, 256> code{}, linear{};
    SrgbLut() {
        for (int k = 0; k < 256; ++k) {
            code[k] = float(k) / 255.0f;
            linear[k] = srgb_to_linear(code[k]);
        }
    }
    float operator()(float v) const {
        const float s = v * 255.0f + 0.5f;
        if (s >= 0.0f && s < 256.0f) {
            const int k = int(s);
            if (code[k] == v) return linear[k];
        }
        return srgb_to_linear(v);
    }
};
const SrgbLut& srgb_lut() {
    static const SrgbLut lut;
    return lut;
}

inline float clamp01(float v) { return std::min(std::max(v, 0.0f), 1.0f); }

// Hot kernels, compiled for AVX2 and for baseline x86-64 and picked at load time. The results are
// identical either way: no FMA contraction (-ffp-contract=off), only correctly rounded IEEE
// operations, same order per element.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define IBLCHECK_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define IBLCHECK_SIMD_CLONES
#endif

// acc[x] = sum_k taps[k] * src[k][x], k ascending (the tool's tap order). For the horizontal
// pass src[k] = row + k; for the vertical pass src[k] is the clamped row y + k - r.
// Register-blocked over 16 / 8 pixels (GCC vector extension; two SSE halves on the baseline
// clone, one AVX register on the AVX2 clone) so the accumulators never round-trip through memory.
typedef float v8f __attribute__((vector_size(32)));
__attribute__((always_inline)) inline v8f load8(const float* p) {
    v8f v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
__attribute__((always_inline)) inline void store8(float* p, v8f v) { std::memcpy(p, &v, sizeof v); }

IBLCHECK_SIMD_CLONES
void fir_accumulate(const float* const* src, const float* taps, int ntaps, int n, float* __restrict acc) {
    int x = 0;
    for (; x + 16 <= n; x += 16) {
        const v8f t0 = v8f{} + taps[0];
        v8f a = v8f{} + t0 * load8(src[0] + x);
        v8f b = v8f{} + t0 * load8(src[0] + x + 8);
        for (int k = 1; k < ntaps; ++k) {
            const v8f t = v8f{} + taps[k];
            a += t * load8(src[k] + x);
            b += t * load8(src[k] + x + 8);
        }
        store8(acc + x, a);
        store8(acc + x + 8, b);
    }
    for (; x + 8 <= n; x += 8) {
        v8f a = v8f{} + (v8f{} + taps[0]) * load8(src[0] + x);
        for (int k = 1; k < ntaps; ++k) a += (v8f{} + taps[k]) * load8(src[k] + x);
        store8(acc + x, a);
    }
    for (; x < n; ++x) {
        float a = 0.0f + taps[0] * src[0][x];
        for (int k = 1; k < ntaps; ++k) a += taps[k] * src[k][x];
        acc[x] = a;
    }
}

// Linear RGB row -> YCxCz (padded output, offset by `pad`) and normalised Y for features.
IBLCHECK_SIMD_CLONES
void rgb_row_to_ycxcz(const float* __restrict R, const float* __restrict G, const float* __restrict B,
                      int n, float* __restrict Y, float* __restrict Cx, float* __restrict Cz) {
    for (int x = 0; x < n; ++x) {
        float X, Yy, Z;
        linear_rgb_to_xyz(R[x], G[x], B[x], X, Yy, Z);
        xyz_to_ycxcz(X, Yy, Z, Y[x], Cx[x], Cz[x]);
    }
}

inline float lab_f_fast(float t) {
    constexpr float delta = 6.0f / 29.0f;
    constexpr float delta_cube = delta * delta * delta;
    constexpr float factor = 1.0f / (3.0f * delta * delta);
    constexpr float term = 4.0f / 29.0f;
    const float c = fast_cbrt(t > delta_cube ? t : delta_cube);
    return t > delta_cube ? c : factor * t + term;
}

// Filtered YCxCz may leave the gamut: clamp in linear RGB, then CIELab with Hunt (Eq. 4).
inline void to_hunt_lab(float Y, float Cx, float Cz, float& L, float& a, float& b) {
    float X, Yy, Z, r, g, bl;
    ycxcz_to_xyz(Y, Cx, Cz, X, Yy, Z);
    xyz_to_linear_rgb(X, Yy, Z, r, g, bl);
    r = std::min(std::max(r, 0.0f), 1.0f);
    g = std::min(std::max(g, 0.0f), 1.0f);
    bl = std::min(std::max(bl, 0.0f), 1.0f);
    linear_rgb_to_xyz(r, g, bl, X, Yy, Z);
    const float fx = lab_f_fast(X * kInvD65[0]);
    const float fy = lab_f_fast(Yy * kInvD65[1]);
    const float fz = lab_f_fast(Z * kInvD65[2]);
    L = 116.0f * fy - 16.0f;
    a = hunt(L, 500.0f * (fx - fy));
    b = hunt(L, 200.0f * (fy - fz));
}

// Per-pixel FLIP from the vertically filtered planes. q[img * 8 + i], i: Y, Cx, Cz1, Cz2, dx,
// ddx, dy, ddy.
IBLCHECK_SIMD_CLONES
void flip_pixels(const float* const* q, int n, float cmax, float pccmax, float* __restrict out) {
    const float norm = 1.0f / std::sqrt(2.0f);
#pragma GCC ivdep
    for (int x = 0; x < n; ++x) {
        // Colour difference (FLIP paper, Eqs. 4-7).
        float Lr, ar, br, Lt, at, bt;
        to_hunt_lab(q[0][x], q[1][x], q[2][x] + q[3][x], Lr, ar, br);
        to_hunt_lab(q[8][x], q[9][x], q[10][x] + q[11][x], Lt, at, bt);
        const float da = ar - at, db = br - bt;
        const float dist = std::fabs(Lr - Lt) + std::sqrt(da * da + db * db);
        const float c = fast_pow(dist, kQc);
        // Eq. 7: [0, pc*cmax] -> [0, pt], [pc*cmax, cmax] -> [pt, 1].
        const float cdiff = c < pccmax ? c * (kPt / pccmax)
                                       : kPt + ((c - pccmax) / (cmax - pccmax)) * (1.0f - kPt);
        // Feature difference (FLIP paper, Eq. 9).
        const float dxr = q[4][x], ddxr = q[5][x], dyr = q[6][x], ddyr = q[7][x];
        const float dxt = q[12][x], ddxt = q[13][x], dyt = q[14][x], ddyt = q[15][x];
        const float edge = std::fabs(std::sqrt(dxr * dxr + dyr * dyr) - std::sqrt(dxt * dxt + dyt * dyt));
        const float point = std::fabs(std::sqrt(ddxr * ddxr + ddyr * ddyr) - std::sqrt(ddxt * ddxt + ddyt * ddyt));
        const float fdiff = std::sqrt(norm * (edge > point ? edge : point)); // ^qf, qf = 0.5
        // Eq. 10: features sharpen the colour error towards 1.
        out[x] = fast_pow(cdiff, 1.0f - fdiff);
    }
}

class FlipEngine {
  public:
    FlipEngine(int w, int h, float ppd, int threads)
        : w_(w), h_(h), threads_(resolve_threads(threads)), sf_(make_spatial_filters(ppd)),
          ff_(make_feature_filters(ppd)) {
        cmax_ = max_color_distance();
        pccmax_ = kPc * cmax_;
        pad_ = std::max(sf_.radius, ff_.radius);
        for (auto& img : planes_)
            for (auto& p : img) p.resize(size_t(w_) * h_);
    }

    // One LDR-FLIP evaluation. prep(img, y, R, G, B) writes row y of image img (0 reference,
    // 1 test) as linear RGB in [0,1]. With max_merge, out = max(out, FLIP) per pixel (HDR),
    // otherwise out = FLIP.
    template <class Prep> void evaluate(const Prep& prep, float* out, bool max_merge) {
        parallel_rows(h_, threads_, [&](int y0, int y1) { horizontal_pass(prep, y0, y1); });
        parallel_rows(h_, threads_, [&](int y0, int y1) { vertical_pass(out, max_merge, y0, y1); });
    }

  private:
    template <class Prep> void horizontal_pass(const Prep& prep, int y0, int y1) {
        const int pw = w_ + 2 * pad_;
        std::vector<float> R(w_), G(w_), B(w_);
        std::vector<float> Y(pw), Cx(pw), Cz(pw), Yn(pw);
        std::vector<const float*> src(2 * pad_ + 1);
        for (int img = 0; img < 2; ++img) {
            auto& P = planes_[img];
            for (int y = y0; y < y1; ++y) {
                prep(img, y, R.data(), G.data(), B.data());
                rgb_row_to_ycxcz(R.data(), G.data(), B.data(), w_, Y.data() + pad_, Cx.data() + pad_,
                                 Cz.data() + pad_);
                // Clamp-to-edge borders, as the tool clamps the tap coordinate.
                for (int i = 0; i < pad_; ++i) {
                    Y[i] = Y[pad_], Cx[i] = Cx[pad_], Cz[i] = Cz[pad_];
                    Y[pad_ + w_ + i] = Y[pad_ + w_ - 1];
                    Cx[pad_ + w_ + i] = Cx[pad_ + w_ - 1];
                    Cz[pad_ + w_ + i] = Cz[pad_ + w_ - 1];
                }
                // Feature detection runs on Y normalised to [0,1] (FLIP paper, Sec. 4.2).
                const float one_over_116 = 1.0f / 116.0f, sixteen_over_116 = 16.0f / 116.0f;
                for (int i = 0; i < pw; ++i) Yn[i] = Y[i] * one_over_116 + sixteen_over_116;

                const size_t row = size_t(y) * w_;
                auto run = [&](const std::vector<float>& in, int radius, const std::vector<float>& taps,
                               Plane plane) {
                    const float* base = in.data() + (pad_ - radius);
                    for (size_t k = 0; k < taps.size(); ++k) src[k] = base + k;
                    fir_accumulate(src.data(), taps.data(), int(taps.size()), w_, P[plane].data() + row);
                };
                run(Y, sf_.radius, sf_.y, kPY);
                run(Cx, sf_.radius, sf_.cx, kPCx);
                run(Cz, sf_.radius, sf_.cz1, kPCz1);
                run(Cz, sf_.radius, sf_.cz2, kPCz2);
                run(Yn, ff_.radius, ff_.dg, kPDx);
                run(Yn, ff_.radius, ff_.ddg, kPDdx);
                run(Yn, ff_.radius, ff_.g, kPG);
            }
        }
    }

    void vertical_pass(float* out, bool max_merge, int y0, int y1) const {
        constexpr int kTile = 512;
        std::vector<float> acc(16 * kTile), err(kTile);
        const float* q[16];
        for (int i = 0; i < 16; ++i) q[i] = acc.data() + i * kTile;
        std::vector<const float*> src(2 * pad_ + 1);
        auto column = [&](const std::vector<float>& plane, const std::vector<float>& taps, int y,
                          int x0, int n, int slot) {
            const int r = int(taps.size()) / 2;
            for (int k = 0; k < int(taps.size()); ++k) {
                const int yy = std::min(std::max(y + k - r, 0), h_ - 1);
                src[k] = plane.data() + size_t(yy) * w_ + x0;
            }
            fir_accumulate(src.data(), taps.data(), int(taps.size()), n, acc.data() + slot * kTile);
        };
        for (int y = y0; y < y1; ++y) {
            for (int x0 = 0; x0 < w_; x0 += kTile) {
                const int n = std::min(kTile, w_ - x0);
                for (int img = 0; img < 2; ++img) {
                    const auto& P = planes_[img];
                    const int s = img * 8;
                    column(P[kPY], sf_.y, y, x0, n, s + 0);
                    column(P[kPCx], sf_.cx, y, x0, n, s + 1);
                    column(P[kPCz1], sf_.cz1, y, x0, n, s + 2);
                    column(P[kPCz2], sf_.cz2, y, x0, n, s + 3);
                    column(P[kPDx], ff_.g, y, x0, n, s + 4);  // d/dx: G'(x) G(y)
                    column(P[kPDdx], ff_.g, y, x0, n, s + 5); // d2/dx2: G''(x) G(y)
                    column(P[kPG], ff_.dg, y, x0, n, s + 6);  // d/dy: G(x) G'(y)
                    column(P[kPG], ff_.ddg, y, x0, n, s + 7); // d2/dy2: G(x) G''(y)
                }
                flip_pixels(q, n, cmax_, pccmax_, err.data());
                float* dst = out + size_t(y) * w_ + x0;
                if (max_merge) {
                    for (int x = 0; x < n; ++x) dst[x] = err[x] > dst[x] ? err[x] : dst[x];
                } else {
                    std::memcpy(dst, err.data(), sizeof(float) * n);
                }
            }
        }
    }

    int w_, h_, threads_;
    SpatialFilters sf_;
    FeatureFilters ff_;
    float cmax_ = 0, pccmax_ = 0;
    int pad_ = 0;
    std::array<std::array<std::vector<float>, kNumPlanes>, 2> planes_;
};

void check_pair(const cv::Mat& a, const cv::Mat& b, const char* what) {
    if (a.empty() || b.empty()) throw InputError(std::string(what) + ": empty image");
    if (a.type() != CV_32FC3 || b.type() != CV_32FC3)
        throw InputError(std::string(what) + ": images must be CV_32FC3 (RGB float)");
    if (a.size() != b.size())
        throw InputError(std::string(what) + ": size mismatch " + std::to_string(a.cols) + "x" +
                         std::to_string(a.rows) + " vs " + std::to_string(b.cols) + "x" +
                         std::to_string(b.rows));
}

} // namespace

flip::ExposureRange flip_auto_exposure_range(const cv::Mat& ref_linear, flip::ToneMapper tm) {
    std::vector<float> lum;
    lum.reserve(size_t(ref_linear.rows) * ref_linear.cols);
    for (int y = 0; y < ref_linear.rows; ++y) {
        const float* p = ref_linear.ptr<float>(y);
        for (int x = 0; x < ref_linear.cols; ++x, p += 3)
            lum.push_back(0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]);
    }
    return flip::auto_exposure_range(tm, std::move(lum));
}

namespace {
// The tool's exposure rule over the pixels with positive luminance only.
flip::ExposureRange lit_exposure_range(const cv::Mat& linear, flip::ToneMapper tm) {
    std::vector<float> lum;
    for (int y = 0; y < linear.rows; ++y) {
        const float* p = linear.ptr<float>(y);
        for (int x = 0; x < linear.cols; ++x, p += 3)
            if (float l = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; l > 0) lum.push_back(l);
    }
    if (lum.empty()) return {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
    return flip::auto_exposure_range(tm, std::move(lum));
}
} // namespace

FlipResult compute_flip_ldr(const cv::Mat& ref_srgb, const cv::Mat& test_srgb, const FlipOptions& opts) {
    check_pair(ref_srgb, test_srgb, "FLIP");
    const int w = ref_srgb.cols, h = ref_srgb.rows;
    const float ppd = float(opts.ppd);
    FlipResult r;
    r.mode = "ldr";
    r.ppd = ppd;
    r.errmap.create(h, w, CV_32F);
    FlipEngine engine(w, h, ppd, opts.threads);
    const SrgbLut& lut = srgb_lut();
    const cv::Mat* imgs[2] = {&ref_srgb, &test_srgb};
    auto prep = [&](int img, int y, float* R, float* G, float* B) {
        const float* p = imgs[img]->ptr<float>(y);
        for (int x = 0; x < w; ++x, p += 3) {
            R[x] = clamp01(lut(p[0]));
            G[x] = clamp01(lut(p[1]));
            B[x] = clamp01(lut(p[2]));
        }
    };
    engine.evaluate(prep, r.errmap.ptr<float>(), false);
    pool_flip_errmap(r);
    return r;
}

FlipResult compute_flip_hdr(const cv::Mat& ref_linear, const cv::Mat& test_linear, const FlipOptions& opts) {
    check_pair(ref_linear, test_linear, "HDR-FLIP");
    const int w = ref_linear.cols, h = ref_linear.rows;
    const float ppd = float(opts.ppd);
    FlipResult r;
    r.mode = "hdr";
    r.ppd = ppd;

    float start, stop;
    r.exposure_source = "given";
    if (!opts.start_exposure || !opts.stop_exposure) {
        // The tool takes the range from the reference's luminance (max and median). A black
        // reference has neither: the tool then gets infinite exposures and scores any test 0 (a
        // silent pass). Take the range from the test instead and say so; if both are black they are
        // equal and every exposure gives 0, so any finite range is right.
        // A reference lit in less than half its pixels has a black median (stop = +inf): its
        // median is then taken over the lit pixels.
        ExposureRange er = flip_auto_exposure_range(ref_linear, opts.tone_mapper);
        r.exposure_source = "reference";
        if (std::isfinite(er.start) && !std::isfinite(er.stop)) {
            er = lit_exposure_range(ref_linear, opts.tone_mapper);
            r.exposure_source = "reference (median of its lit pixels)";
        }
        if (!std::isfinite(er.start) || !std::isfinite(er.stop)) {
            er = lit_exposure_range(test_linear, opts.tone_mapper);
            r.exposure_source = "test (the reference is black)";
        }
        if (!std::isfinite(er.start) || !std::isfinite(er.stop)) {
            er = {0.0f, 0.0f};
            r.exposure_source = "none (both images are black)";
        }
        start = opts.start_exposure.value_or(er.start);
        stop = opts.stop_exposure.value_or(er.stop);
    } else {
        start = *opts.start_exposure;
        stop = *opts.stop_exposure;
    }
    if (!(start <= stop))
        throw UsageError("HDR-FLIP: start exposure (" + std::to_string(start) +
                         ") must not exceed stop exposure (" + std::to_string(stop) + ")");
    const int num = opts.num_exposures.value_or(auto_num_exposures(start, stop));
    if (num < 2) throw UsageError("HDR-FLIP: at least 2 exposures are needed");
    r.start_exposure = start;
    r.stop_exposure = stop;
    r.num_exposures = num;

    r.errmap = cv::Mat::zeros(h, w, CV_32F);
    FlipEngine engine(w, h, ppd, opts.threads);
    const cv::Mat* imgs[2] = {&ref_linear, &test_linear};
    const float step = (stop - start) / float(num - 1);
    const ToneMapper tm = opts.tone_mapper;
    for (int i = 0; i < num; ++i) {
        const float exposure = start + float(i) * step;
        const float m = std::pow(2.0f, exposure);
        auto prep = [&](int img, int y, float* R, float* G, float* B) {
            const float* p = imgs[img]->ptr<float>(y);
            for (int x = 0; x < w; ++x, p += 3) {
                float cr = p[0] * m, cg = p[1] * m, cb = p[2] * m;
                tone_map(tm, cr, cg, cb);
                R[x] = clamp01(cr);
                G[x] = clamp01(cg);
                B[x] = clamp01(cb);
            }
        };
        engine.evaluate(prep, r.errmap.ptr<float>(), true);
    }
    pool_flip_errmap(r);
    return r;
}

void pool_flip_errmap(FlipResult& r) {
    const cv::Mat& e = r.errmap;
    const int w = e.cols, h = e.rows;
    if (w == 0 || h == 0) return;
    double sum = 0.0;
    float sum_float = 0.0f; // the tool's single-precision total, used by its weighted percentiles
    float mn = e.at<float>(0, 0), mx = mn;
    std::vector<float> values;
    values.reserve(size_t(w) * h);
    bool negative = false;
    for (int y = 0; y < h; ++y) {
        const float* p = e.ptr<float>(y);
        for (int x = 0; x < w; ++x) {
            const float v = p[x];
            sum += double(v);
            sum_float += v;
            mn = std::min(mn, v);
            mx = std::max(mx, v);
            negative |= !(v >= 0.0f);
            values.push_back(v);
        }
    }
    const size_t n = values.size();
    r.mean = sum / double(n);
    r.min = mn;
    r.max = mx;
    if (negative) std::sort(values.begin(), values.end()); // not a FLIP map; stay correct
    else radix_sort_nonnegative(values);
    r.weighted_median = weighted_percentile_sorted(values, sum_float, 0.5f);
    r.weighted_q1 = weighted_percentile_sorted(values, sum_float, 0.25f);
    r.weighted_q3 = weighted_percentile_sorted(values, sum_float, 0.75f);
    // Nearest-rank 99th percentile.
    const size_t rank = std::min(n - 1, size_t(std::ceil(0.99 * double(n))) - 1);
    r.p99 = values[rank];

    // Worst 16x16 block: where a reviewer should look first.
    constexpr int kBlock = 16;
    r.block_max = -1.0;
    for (int by = 0; by < h; by += kBlock) {
        for (int bx = 0; bx < w; bx += kBlock) {
            double s = 0.0;
            const int ye = std::min(h, by + kBlock), xe = std::min(w, bx + kBlock);
            for (int y = by; y < ye; ++y) {
                const float* p = e.ptr<float>(y);
                for (int x = bx; x < xe; ++x) s += double(p[x]);
            }
            const double m = s / double((ye - by) * (xe - bx));
            if (m > r.block_max) {
                r.block_max = m;
                r.block_x = bx;
                r.block_y = by;
            }
        }
    }
}

} // namespace iblcheck
