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
#include <cstring>
#include <stdexcept>
#include <vector>

#include "harness/common/errors.h"
#include "metrics/flip/color_spaces.h"
#include "metrics/flip/csf_filters.h"
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
        for (int img = 0; img < 2; ++img) {
            auto& P = planes_[img];
            for (int y = y0; y < y1; ++y) {
                prep(img, y, R.data(), G.data(), B.data());
                for (int x = 0; x < w_; ++x) {
                    float X, Yy, Z;
                    linear_rgb_to_xyz(R[x], G[x], B[x], X, Yy, Z);
                    xyz_to_ycxcz(X, Yy, Z, Y[pad_ + x], Cx[pad_ + x], Cz[pad_ + x]);
                }
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
                const int so = pad_ - sf_.radius, fo = pad_ - ff_.radius;
                filter_row(Y.data() + so, sf_.y, P[kPY].data() + row);
                filter_row(Cx.data() + so, sf_.cx, P[kPCx].data() + row);
                filter_row(Cz.data() + so, sf_.cz1, P[kPCz1].data() + row);
                filter_row(Cz.data() + so, sf_.cz2, P[kPCz2].data() + row);
                filter_row(Yn.data() + fo, ff_.dg, P[kPDx].data() + row);
                filter_row(Yn.data() + fo, ff_.ddg, P[kPDdx].data() + row);
                filter_row(Yn.data() + fo, ff_.g, P[kPG].data() + row);
            }
        }
    }

    // out[x] = sum_k taps[k] * in[x + k], k ascending.
    void filter_row(const float* __restrict in, const std::vector<float>& taps,
                    float* __restrict out) const {
        const int n = int(taps.size());
        const float t0 = taps[0];
        for (int x = 0; x < w_; ++x) out[x] = 0.0f + t0 * in[x];
        for (int k = 1; k < n; ++k) {
            const float t = taps[k];
            const float* src = in + k;
            for (int x = 0; x < w_; ++x) out[x] += t * src[x];
        }
    }

    // acc[x] = sum_k taps[k] * plane[clamp(y + k - r)][x0 + x], k ascending.
    void filter_column(const std::vector<float>& plane, const std::vector<float>& taps, int y,
                       int x0, int n, float* __restrict acc) const {
        const int r = int(taps.size()) / 2;
        for (int x = 0; x < n; ++x) acc[x] = 0.0f;
        for (int k = 0; k < int(taps.size()); ++k) {
            const int yy = std::min(std::max(y + k - r, 0), h_ - 1);
            const float t = taps[k];
            const float* __restrict src = plane.data() + size_t(yy) * w_ + x0;
            for (int x = 0; x < n; ++x) acc[x] += t * src[x];
        }
    }

    void vertical_pass(float* out, bool max_merge, int y0, int y1) const {
        constexpr int kTile = 256;
        // Per image: Y, Cx, Cz1, Cz2, dx, ddx, dy, ddy.
        std::vector<float> acc(2 * 8 * kTile);
        auto A = [&](int img, int q) { return acc.data() + (img * 8 + q) * kTile; };
        const float norm = 1.0f / std::sqrt(2.0f);
        for (int y = y0; y < y1; ++y) {
            for (int x0 = 0; x0 < w_; x0 += kTile) {
                const int n = std::min(kTile, w_ - x0);
                for (int img = 0; img < 2; ++img) {
                    const auto& P = planes_[img];
                    filter_column(P[kPY], sf_.y, y, x0, n, A(img, 0));
                    filter_column(P[kPCx], sf_.cx, y, x0, n, A(img, 1));
                    filter_column(P[kPCz1], sf_.cz1, y, x0, n, A(img, 2));
                    filter_column(P[kPCz2], sf_.cz2, y, x0, n, A(img, 3));
                    filter_column(P[kPDx], ff_.g, y, x0, n, A(img, 4));
                    filter_column(P[kPDdx], ff_.g, y, x0, n, A(img, 5));
                    filter_column(P[kPG], ff_.dg, y, x0, n, A(img, 6));
                    filter_column(P[kPG], ff_.ddg, y, x0, n, A(img, 7));
                }
                float* dst = out + size_t(y) * w_ + x0;
                for (int x = 0; x < n; ++x) {
                    const float cdiff = color_difference(
                        A(0, 0)[x], A(0, 1)[x], A(0, 2)[x] + A(0, 3)[x],
                        A(1, 0)[x], A(1, 1)[x], A(1, 2)[x] + A(1, 3)[x]);
                    // Feature difference (FLIP paper, Eq. 9).
                    const float dxr = A(0, 4)[x], ddxr = A(0, 5)[x], dyr = A(0, 6)[x], ddyr = A(0, 7)[x];
                    const float dxt = A(1, 4)[x], ddxt = A(1, 5)[x], dyt = A(1, 6)[x], ddyt = A(1, 7)[x];
                    const float edge_r = std::sqrt(dxr * dxr + dyr * dyr);
                    const float edge_t = std::sqrt(dxt * dxt + dyt * dyt);
                    const float point_r = std::sqrt(ddxr * ddxr + ddyr * ddyr);
                    const float point_t = std::sqrt(ddxt * ddxt + ddyt * ddyt);
                    const float fdiff = std::pow(
                        norm * std::max(std::fabs(edge_r - edge_t), std::fabs(point_r - point_t)), kQf);
                    // Eq. 10: features sharpen the colour error towards 1.
                    const float e = std::pow(cdiff, 1.0f - fdiff);
                    if (max_merge) {
                        if (e > dst[x]) dst[x] = e;
                    } else {
                        dst[x] = e;
                    }
                }
            }
        }
    }

    // Colour difference of two CSF-filtered YCxCz pixels (FLIP paper, Eqs. 4-7).
    float color_difference(float Yr, float Cxr, float Czr, float Yt, float Cxt, float Czt) const {
        float Lr, ar, br, Lt, at, bt;
        to_hunt_lab(Yr, Cxr, Czr, Lr, ar, br);
        to_hunt_lab(Yt, Cxt, Czt, Lt, at, bt);
        float c = std::pow(hyab(Lr, ar, br, Lt, at, bt), kQc);
        // Eq. 7: [0, pc*cmax] -> [0, pt], [pc*cmax, cmax] -> [pt, 1].
        if (c < pccmax_) c *= kPt / pccmax_;
        else c = kPt + ((c - pccmax_) / (cmax_ - pccmax_)) * (1.0f - kPt);
        return c;
    }

    // Filtered YCxCz may leave the gamut: clamp in linear RGB, then CIELab with Hunt (Eq. 4).
    static void to_hunt_lab(float Y, float Cx, float Cz, float& L, float& a, float& b) {
        float X, Yy, Z, r, g, bl;
        ycxcz_to_xyz(Y, Cx, Cz, X, Yy, Z);
        xyz_to_linear_rgb(X, Yy, Z, r, g, bl);
        r = clamp01(r), g = clamp01(g), bl = clamp01(bl);
        linear_rgb_to_xyz(r, g, bl, X, Yy, Z);
        xyz_to_lab(X, Yy, Z, L, a, b);
        a = hunt(L, a);
        b = hunt(L, b);
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
    if (!opts.start_exposure || !opts.stop_exposure) {
        const ExposureRange er = flip_auto_exposure_range(ref_linear, opts.tone_mapper);
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
