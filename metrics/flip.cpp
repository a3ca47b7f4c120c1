// FLIP evaluation engine. The arithmetic of each pixel follows the reference tool (float32, same
// operation order, taps summed from -r to +r); the structure is ours. The image is cut into strips
// of 256 columns; per strip, two passes stream down the rows:
//   H pass: input row -> linear RGB -> YCxCz -> 7 horizontally filtered rows per image
//           (4 CSF planes: Y, Cx, Cz part 1, Cz part 2; 3 feature planes: G', G'', G on Y), kept in
//           a ring of the last 2r+1 rows (no full-image planes: they cost ~120 MB of page faults
//           and memory traffic at 1080p),
//   V pass: vertical filtering of those rows, then colour error, feature error and the final FLIP
//           value per pixel (and the running max over exposures for HDR).
// The loops themselves are in flip/kernels.h (scalar, SSE2 and AVX2 builds, identical results).
// Threads take whole strips, so results do not depend on the thread count.
#include "metrics/flip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "metrics/identical.h"

#include "kernel/errors.h"
#include "kernel/parallel_for.h"
#include "metrics/flip/color_spaces.h"
#include "metrics/flip/csf_filters.h"
#include "metrics/flip/feature_detection.h"
#include "metrics/flip/kernels.h"
#include "metrics/flip/magma_table.h"
#include "metrics/flip/pooling.h"

namespace iblcheck {
namespace {

using namespace flip;

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
};
const SrgbLut& srgb_lut() {
    static const SrgbLut lut;
    return lut;
}

inline float clamp01(float v) { return std::min(std::max(v, 0.0f), 1.0f); }

// Plane indices of the H pass, per image.
enum Plane { kPY = 0, kPCx, kPCz1, kPCz2, kPDx, kPDdx, kPG, kNumPlanes };

// Columns per strip: the ring of horizontally filtered rows of one strip (2 images x 7 planes x
// 2r+1 rows x 256 columns, ~300 KB at 67 ppd) stays in a core's L2 cache while the vertical pass
// reads each row 2r+1 times.
constexpr int kStripWidth = 256;

class FlipEngine {
  public:
    FlipEngine(int w, int h, float ppd, int threads, const Kernels& kernels)
        : w_(w), h_(h), threads_(resolve_threads(threads)), k_(kernels), sf_(make_spatial_filters(ppd)),
          ff_(make_feature_filters(ppd)) {
        cmax_ = max_color_distance();
        pccmax_ = kPc * cmax_;
        pad_ = std::max(sf_.radius, ff_.radius);
        depth_ = 2 * pad_ + 1;
        plan_work();
    }

    // One LDR-FLIP evaluation. prep(img, y, x0, x1, R, G, B) writes columns [x0, x1) of row y of
    // image img (0 reference, 1 test) as linear RGB in [0,1] (R[0] is column x0). With max_merge,
    // out = max(out, FLIP) per pixel (HDR), otherwise out = FLIP.
    // Every output pixel is computed by exactly one item with the same arithmetic: the results do not
    // depend on the thread count or on which thread takes which item.
    template <class Prep> void evaluate(const Prep& prep, float* out, bool max_merge) {
        parallel_for(
            int(items_.size()), threads_, [this] { return Scratch(*this); },
            [&](int i, Scratch& s) { run_item(prep, items_[size_t(i)], s, out, max_merge); });
    }

  private:
    // A rectangle of output pixels computed by one thread: a strip of columns, all rows unless
    // there are fewer strips than threads (then row bands; each band recomputes r rows above and
    // below itself, which gives the same values).
    struct Item {
        int x0, x1, y0, y1;
    };

    // Per-thread buffers, reused across the items a thread computes.
    struct Scratch {
        std::vector<float> rgb, ycc, ring, vacc;
        std::vector<const float*> src; // tap sources: 2r+1 of them, r grows with ppd
        explicit Scratch(const FlipEngine& e) {
            src.resize(size_t(2 * e.pad_ + 1));
            const size_t pw = size_t(e.strip_ + 2 * e.pad_);
            rgb.resize(3 * pw);
            ycc.resize(4 * pw);
            ring.resize(size_t(2) * kNumPlanes * e.depth_ * e.strip_);
            vacc.resize(size_t(16) * e.strip_);
        }
    };

    void plan_work() {
        strip_ = std::min(kStripWidth, w_);
        const int strips = (w_ + strip_ - 1) / strip_;
        int bands = 1;
        if (strips < threads_) bands = std::max(1, std::min((threads_ + strips - 1) / strips, h_ / 64));
        const int band_h = (h_ + bands - 1) / bands;
        for (int b = 0; b < bands; ++b)
            for (int sx = 0; sx < strips; ++sx) {
                const int y0 = b * band_h, y1 = std::min(h_, y0 + band_h);
                if (y0 < y1) items_.push_back({sx * strip_, std::min(w_, (sx + 1) * strip_), y0, y1});
            }
    }

    float* ring_row(Scratch& s, int img, int plane, int y) const {
        return s.ring.data() + ((size_t(img) * kNumPlanes + plane) * depth_ + size_t(y % depth_)) * strip_;
    }

    // Horizontal pass of row y, columns [x0, x1), both images: 7 filtered planes into the ring.
    template <class Prep> void horizontal_row(const Prep& prep, const Item& it, int y, Scratch& s) const {
        const int n = it.x1 - it.x0, pw = n + 2 * pad_;
        const size_t stride = size_t(strip_ + 2 * pad_);
        float *R = s.rgb.data(), *G = R + stride, *B = G + stride;
        float *Y = s.ycc.data(), *Cx = Y + stride, *Cz = Cx + stride, *Yn = Cz + stride;
        // Input columns x0 - pad .. x1 + pad, clamped to the image (the tool clamps tap coordinates).
        const int xa = std::max(0, it.x0 - pad_), xb = std::min(w_, it.x1 + pad_);
        const int lo = xa - (it.x0 - pad_), hi = lo + (xb - xa);
        for (int img = 0; img < 2; ++img) {
            prep(img, y, xa, xb, R + lo, G + lo, B + lo);
            k_.rgb_to_ycxcz(R + lo, G + lo, B + lo, xb - xa, Y + lo, Cx + lo, Cz + lo, Yn + lo);
            for (float* c : {Y, Cx, Cz, Yn}) {
                for (int i = 0; i < lo; ++i) c[i] = c[lo];
                for (int i = hi; i < pw; ++i) c[i] = c[hi - 1];
            }
            auto run = [&](const float* in, int radius, std::initializer_list<const std::vector<float>*> taps,
                           std::initializer_list<Plane> planes) {
                const float** src = s.src.data();
                const float* tp[3];
                float* dst[3];
                const int ntaps = 2 * radius + 1;
                for (int k = 0; k < ntaps; ++k) src[k] = in + (pad_ - radius) + k;
                int f = 0;
                for (const auto* t : taps) tp[f++] = t->data();
                f = 0;
                for (Plane p : planes) dst[f++] = ring_row(s, img, p, y);
                k_.fir(src, tp, f, ntaps, n, dst);
            };
            run(Y, sf_.radius, {&sf_.y}, {kPY});
            run(Cx, sf_.radius, {&sf_.cx}, {kPCx});
            run(Cz, sf_.radius, {&sf_.cz1, &sf_.cz2}, {kPCz1, kPCz2});
            run(Yn, ff_.radius, {&ff_.dg, &ff_.ddg, &ff_.g}, {kPDx, kPDdx, kPG});
        }
    }

    // Vertical pass of row y for the item's columns, then FLIP per pixel into out.
    void vertical_row(const Item& it, int y, Scratch& s, float* out, bool max_merge) const {
        const int n = it.x1 - it.x0;
        const float* q[16];
        for (int i = 0; i < 16; ++i) q[i] = s.vacc.data() + size_t(i) * strip_;
        auto column = [&](int img, Plane plane, std::initializer_list<const std::vector<float>*> taps,
                          std::initializer_list<int> slots) {
            const float** src = s.src.data();
            const float* tp[3];
            float* dst[3];
            const int ntaps = int((*taps.begin())->size()), r = ntaps / 2;
            for (int k = 0; k < ntaps; ++k) src[k] = ring_row(s, img, plane, std::min(std::max(y + k - r, 0), h_ - 1));
            int f = 0;
            for (const auto* t : taps) tp[f++] = t->data();
            f = 0;
            for (int slot : slots) dst[f++] = s.vacc.data() + size_t(img * 8 + slot) * strip_;
            k_.fir(src, tp, f, ntaps, n, dst);
        };
        for (int img = 0; img < 2; ++img) {
            column(img, kPY, {&sf_.y}, {0});
            column(img, kPCx, {&sf_.cx}, {1});
            column(img, kPCz1, {&sf_.cz1}, {2});
            column(img, kPCz2, {&sf_.cz2}, {3});
            column(img, kPDx, {&ff_.g}, {4});              // d/dx: G'(x) G(y)
            column(img, kPDdx, {&ff_.g}, {5});             // d2/dx2: G''(x) G(y)
            column(img, kPG, {&ff_.dg, &ff_.ddg}, {6, 7}); // d/dy: G(x) G'(y); d2/dy2: G(x) G''(y)
        }
        k_.flip_pixels(q, n, cmax_, pccmax_, out + size_t(y) * w_ + it.x0, max_merge);
    }

    template <class Prep> void run_item(const Prep& prep, const Item& it, Scratch& s, float* out, bool max_merge) const {
        int next = std::max(0, it.y0 - pad_); // next row of the horizontal pass
        for (int y = it.y0; y < it.y1; ++y) {
            for (const int last = std::min(h_ - 1, y + pad_); next <= last; ++next) horizontal_row(prep, it, next, s);
            vertical_row(it, y, s, out, max_merge);
        }
    }

    int w_, h_, threads_;
    const Kernels& k_;
    SpatialFilters sf_;
    FeatureFilters ff_;
    float cmax_ = 0, pccmax_ = 0;
    int pad_ = 0, depth_ = 0, strip_ = 0;
    std::vector<Item> items_;
};

// --ppd 1e39 became inf (and 1e-39 an infinite pixel pitch): FLIP 0.0 for any pair. From 1 pixel per
// degree the filters are at least a pixel wide; at 1000 their radius is 135 pixels (10 at 67).
void check_ppd(double ppd, const char* what) {
    if (!(ppd >= 1 && ppd <= 1000)) throw UsageError(fmt::format("{}: ppd {:g} is not in 1..1000 pixels per degree", what, ppd));
}

// Given exposures: 2^e must be a normal float (126 stops either way), and the range one FLIP
// evaluation per stop (-100000..100000 ran for ever; -1e30..1e30 overflowed the exposure count).
void check_given_exposure(float e, const char* which) {
    if (!(std::fabs(e) <= 126.0f))
        throw UsageError(fmt::format("HDR-FLIP: {} exposure {:g} is not in -126..126 stops", which, e));
}

void check_pair(const cv::Mat& a, const cv::Mat& b, const char* what) {
    if (a.empty() || b.empty()) throw InputError(std::string(what) + ": empty image");
    if (a.type() != CV_32FC3 || b.type() != CV_32FC3)
        throw InputError(std::string(what) + ": images must be CV_32FC3 (RGB float)");
    if (a.size() != b.size())
        throw InputError(std::string(what) + ": size mismatch " + std::to_string(a.cols) + "x" + std::to_string(a.rows) + " vs " +
                         std::to_string(b.cols) + "x" + std::to_string(b.rows));
}

} // namespace

flip::ExposureRange flip_auto_exposure_range(const cv::Mat& ref_linear, flip::ToneMapper tm) {
    std::vector<float> lum;
    lum.reserve(size_t(ref_linear.rows) * ref_linear.cols);
    for (int y = 0; y < ref_linear.rows; ++y) {
        const float* p = ref_linear.ptr<float>(y);
        for (int x = 0; x < ref_linear.cols; ++x, p += 3) lum.push_back(0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]);
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
    check_ppd(opts.ppd, "FLIP");
    const int w = ref_srgb.cols, h = ref_srgb.rows;
    const float ppd = float(opts.ppd);
    FlipResult r;
    r.mode = "ldr";
    r.ppd = ppd;
    r.errmap.create(h, w, CV_32F);
    const Kernels& kern = opts.kernels ? *opts.kernels : default_kernels();
    FlipEngine engine(w, h, ppd, opts.threads, kern);
    const SrgbLut& lut = srgb_lut();
    const cv::Mat* imgs[2] = {&ref_srgb, &test_srgb};
    auto prep = [&](int img, int y, int x0, int x1, float* R, float* G, float* B) {
        const float* p = imgs[img]->ptr<float>(y) + 3 * x0;
        const int n = x1 - x0;
        kern.srgb_to_linear(p, n, lut.code.data(), lut.linear.data(), R, G, B);
        // Values that are not 8-bit codes (-1 from the table): the formula.
        for (int i = 0; i < n; ++i) {
            if (R[i] < 0.0f) R[i] = clamp01(srgb_to_linear(p[3 * i]));
            if (G[i] < 0.0f) G[i] = clamp01(srgb_to_linear(p[3 * i + 1]));
            if (B[i] < 0.0f) B[i] = clamp01(srgb_to_linear(p[3 * i + 2]));
        }
    };
    engine.evaluate(prep, r.errmap.ptr<float>(), false);
    pool_flip_errmap(r);
    return r;
}

FlipResult compute_flip_hdr(const cv::Mat& ref_linear, const cv::Mat& test_linear, const FlipOptions& opts) {
    check_pair(ref_linear, test_linear, "HDR-FLIP");
    check_ppd(opts.ppd, "HDR-FLIP");
    if (opts.start_exposure) check_given_exposure(*opts.start_exposure, "start");
    if (opts.stop_exposure) check_given_exposure(*opts.stop_exposure, "stop");
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
        throw UsageError("HDR-FLIP: start exposure (" + std::to_string(start) + ") must not exceed stop exposure (" +
                         std::to_string(stop) + ")");
    const int num = opts.num_exposures.value_or(auto_num_exposures(start, stop));
    if (num < 2) throw UsageError("HDR-FLIP: at least 2 exposures are needed");
    r.start_exposure = start;
    r.stop_exposure = stop;
    r.num_exposures = num;

    // Not cv::Mat::zeros: its MatExpr goes through a lazily built OpenCV singleton that TSan sees
    // racing between the runner's workers.
    r.errmap = cv::Mat(h, w, CV_32F, cv::Scalar(0));
    if (opts.skip_identical && identical_finite(ref_linear, test_linear)) {
        pool_flip_errmap(r);
        return r;
    }
    const Kernels& kern = opts.kernels ? *opts.kernels : default_kernels();
    FlipEngine engine(w, h, ppd, opts.threads, kern);
    const cv::Mat* imgs[2] = {&ref_linear, &test_linear};
    const float step = (stop - start) / float(num - 1);
    const ToneMapper tm = opts.tone_mapper;
    for (int i = 0; i < num; ++i) {
        const float exposure = start + float(i) * step;
        const float m = std::pow(2.0f, exposure);
        auto prep = [&](int img, int y, int x0, int x1, float* R, float* G, float* B) {
            kern.expose_tone_map(imgs[img]->ptr<float>(y) + 3 * x0, x1 - x0, m, tm, R, G, B);
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
    if (negative)
        std::sort(values.begin(), values.end()); // not a FLIP map; stay correct
    else
        radix_sort_nonnegative(values);
    const auto wp = weighted_percentiles_sorted<3>(values, sum_float, {0.5f, 0.25f, 0.75f});
    r.weighted_median = wp[0];
    r.weighted_q1 = wp[1];
    r.weighted_q3 = wp[2];
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
