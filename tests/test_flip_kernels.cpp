// The FLIP kernel variants (metrics/flip/kernels.h) give the same bits: the scalar reference, the
// SSE2 build and (on a CPU with it) the AVX2 build, kernel by kernel on random data and end to end
// on LDR and HDR pairs of awkward sizes, at any thread count (issue 15: a FLIP value must not
// depend on the CI machine's SIMD width).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "kernel/errors.h"
#include "metrics/flip.h"
#include "metrics/flip/kernels.h"
#include "metrics/flip/pooling.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_flip_kernels {

namespace {

bool same_bits(const float* a, const float* b, size_t n) { return std::memcmp(a, b, n * sizeof(float)) == 0; }

std::vector<float> random_values(size_t n, unsigned seed, float lo, float hi) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(lo, hi);
    std::vector<float> v(n);
    for (auto& x : v) x = u(rng);
    return v;
}

cv::Mat test_image(int w, int h, unsigned seed, bool hdr) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const float smooth = 0.5f + 0.4f * std::sin(0.13f * float(x + 7 * c) + 0.05f * float(y));
                float v = std::min(1.0f, std::max(0.0f, smooth + 0.2f * (u(rng) - 0.5f)));
                m.ptr<float>(y)[3 * x + c] =
                    hdr ? v * std::exp2(12.0f * float(x) / float(w) - 6.0f) : std::round(v * 255.0f) / 255.0f;
            }
    return m;
}

class KernelVariants : public ::testing::TestWithParam<const flip::Kernels*> {};

TEST_P(KernelVariants, FirMatchesScalarBitForBit) {
    const flip::Kernels& k = *GetParam();
    const flip::Kernels& ref = flip::scalar_kernels();
    for (int nf = 1; nf <= 3; ++nf)
        for (int ntaps : {1, 19, 21})
            for (int n : {1, 7, 8, 9, 15, 16, 17, 31, 33, 48, 63, 65, 256}) {
                const std::vector<float> data = random_values(size_t(n + ntaps) * 2, unsigned(nf * 1000 + n), -50, 50);
                std::vector<const float*> src(static_cast<size_t>(ntaps));
                for (int i = 0; i < ntaps; ++i) src[size_t(i)] = data.data() + i; // the horizontal pass's layout
                std::vector<std::vector<float>> taps(3), out_k(3, std::vector<float>(size_t(n))),
                    out_r(3, std::vector<float>(size_t(n)));
                const float* tp[3];
                float *ok[3], *orf[3];
                for (int f = 0; f < 3; ++f) {
                    taps[size_t(f)] = random_values(size_t(ntaps), unsigned(f + 7 * ntaps), -1, 1);
                    taps[size_t(f)][size_t(ntaps / 2)] = -0.0f; // the derivative filter's centre tap
                    tp[f] = taps[size_t(f)].data();
                    ok[f] = out_k[size_t(f)].data();
                    orf[f] = out_r[size_t(f)].data();
                }
                k.fir(src.data(), tp, nf, ntaps, n, ok);
                ref.fir(src.data(), tp, nf, ntaps, n, orf);
                for (int f = 0; f < nf; ++f)
                    ASSERT_TRUE(same_bits(ok[f], orf[f], size_t(n)))
                        << k.name << " nf=" << nf << " ntaps=" << ntaps << " n=" << n << " filter " << f;
            }
}

TEST_P(KernelVariants, PixelMathMatchesScalarBitForBit) {
    const flip::Kernels& k = *GetParam();
    const flip::Kernels& ref = flip::scalar_kernels();
    const int n = 1037;
    // Colour conversion on [0,1] and beyond (tone-mapped inputs are clamped, filtered ones are not).
    const auto r = random_values(n, 1, -0.1f, 1.1f), g = random_values(n, 2, 0, 1), b = random_values(n, 3, 0, 1);
    std::vector<float> o1(4 * n), o2(4 * n);
    k.rgb_to_ycxcz(r.data(), g.data(), b.data(), n, &o1[0], &o1[n], &o1[2 * n], &o1[3 * n]);
    ref.rgb_to_ycxcz(r.data(), g.data(), b.data(), n, &o2[0], &o2[n], &o2[2 * n], &o2[3 * n]);
    EXPECT_TRUE(same_bits(o1.data(), o2.data(), o1.size())) << k.name;
    // sRGB codes through the table: exact codes k/255, values that are not (misses give -1), NaN,
    // out of range; and HDR exposure + tone mapping with each tone mapper.
    std::vector<float> rgb = random_values(3 * n, 4, -0.2f, 1.2f);
    for (int i = 0; i < 3 * n; i += 2) rgb[size_t(i)] = float(i % 256) / 255.0f;
    rgb[5] = std::numeric_limits<float>::quiet_NaN();
    rgb[7] = -0.0f;
    std::array<float, 256> code, linear;
    for (int i = 0; i < 256; ++i) code[size_t(i)] = float(i) / 255.0f, linear[size_t(i)] = 0.001f * float(i * i) - 0.01f;
    k.srgb_to_linear(rgb.data(), n, code.data(), linear.data(), &o1[0], &o1[n], &o1[2 * n]);
    ref.srgb_to_linear(rgb.data(), n, code.data(), linear.data(), &o2[0], &o2[n], &o2[2 * n]);
    EXPECT_TRUE(same_bits(o1.data(), o2.data(), size_t(3 * n))) << k.name << " srgb_to_linear";
    const std::vector<float> radiance = random_values(3 * n, 5, 0.0f, 300.0f);
    for (auto tm : {flip::ToneMapper::aces, flip::ToneMapper::hable, flip::ToneMapper::reinhard}) {
        k.expose_tone_map(radiance.data(), n, 0.37f, tm, &o1[0], &o1[n], &o1[2 * n]);
        ref.expose_tone_map(radiance.data(), n, 0.37f, tm, &o2[0], &o2[n], &o2[2 * n]);
        EXPECT_TRUE(same_bits(o1.data(), o2.data(), size_t(3 * n))) << k.name << " tone mapper " << int(tm);
    }
    // FLIP per pixel from filtered planes: realistic ranges (Y around 0..100, chroma +-100,
    // derivatives +-1), plus zeros and identical reference/test values.
    std::vector<std::vector<float>> planes(16);
    for (int i = 0; i < 16; ++i) {
        const int c = i % 8;
        planes[size_t(i)] = c == 0  ? random_values(n, unsigned(10 + i), -5, 110)
                            : c < 4 ? random_values(n, unsigned(10 + i), -120, 120)
                                    : random_values(n, unsigned(10 + i), -1, 1);
    }
    for (int x = 0; x < 40; ++x)
        for (int i = 0; i < 8; ++i) planes[size_t(8 + i)][size_t(x)] = planes[size_t(i)][size_t(x)]; // equal pixels
    for (int i = 0; i < 16; ++i) planes[size_t(i)][50] = 0.0f;
    const float* q[16];
    for (int i = 0; i < 16; ++i) q[i] = planes[size_t(i)].data();
    const float cmax = 41.2f, pccmax = 0.4f * cmax;
    for (bool merge : {false, true}) {
        std::vector<float> e1 = random_values(n, 99, 0, 1), e2 = e1;
        k.flip_pixels(q, n, cmax, pccmax, e1.data(), merge);
        ref.flip_pixels(q, n, cmax, pccmax, e2.data(), merge);
        EXPECT_TRUE(same_bits(e1.data(), e2.data(), size_t(n))) << k.name << (merge ? " max-merge" : "");
    }
}

TEST_P(KernelVariants, FlipMatchesScalarBitForBitAtAnyThreadCount) {
    const flip::Kernels& k = *GetParam();
    struct Case {
        int w, h;
        bool hdr;
        double ppd = double(flip::kDefaultPpd);
    };
    // Widths around the 256-column strips and the 8/16/32-pixel blocks; tiny images below the
    // filters' radius; a tall narrow one (row bands when threads > strips).
    for (const Case c : {Case{300, 77, false}, Case{517, 33, true}, Case{7, 9, false}, Case{256, 40, true}, Case{40, 300, false},
                         Case{90, 70, false, 400.0}}) { // 400 ppd: filters of 109 taps
        const cv::Mat a = test_image(c.w, c.h, 1, c.hdr), b = test_image(c.w, c.h, 2, c.hdr);
        FlipOptions ref_opts;
        ref_opts.threads = 1;
        ref_opts.ppd = c.ppd;
        ref_opts.kernels = &flip::scalar_kernels();
        const FlipResult ref = c.hdr ? compute_flip_hdr(a, b, ref_opts) : compute_flip_ldr(a, b, ref_opts);
        ASSERT_GT(ref.mean, 0.0);
        for (int threads : {1, 2, 3}) {
            FlipOptions o = ref_opts;
            o.kernels = &k;
            o.threads = threads;
            const FlipResult r = c.hdr ? compute_flip_hdr(a, b, o) : compute_flip_ldr(a, b, o);
            ASSERT_TRUE(same_bits(r.errmap.ptr<float>(), ref.errmap.ptr<float>(), r.errmap.total()))
                << k.name << " " << c.w << "x" << c.h << (c.hdr ? " hdr" : " ldr") << " threads " << threads;
            EXPECT_EQ(r.mean, ref.mean);
            EXPECT_EQ(r.weighted_median, ref.weighted_median);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Available, KernelVariants, ::testing::ValuesIn(flip::available_kernels()),
                         [](const auto& info) { return std::string(info.param->name); });

TEST(KernelSelection, NamesAndDefault) {
    EXPECT_STREQ(flip::kernels_named("scalar").name, "scalar");
    EXPECT_STREQ(flip::kernels_named("sse2").name, "sse2");
    EXPECT_THROW(flip::kernels_named("avx512"), UsageError);
    if (flip::cpu_has_avx2()) {
        EXPECT_STREQ(flip::kernels_named("avx2").name, "avx2");
        EXPECT_EQ(flip::available_kernels().size(), 3u);
    } else {
        EXPECT_THROW(flip::kernels_named("avx2"), EnvironmentError);
    }
    // The default is the fastest this CPU runs (unless IBLCHECK_FLIP_KERNELS says otherwise).
    if (!std::getenv("IBLCHECK_FLIP_KERNELS")) {
        EXPECT_STREQ(flip::default_kernels().name, flip::cpu_has_avx2() ? "avx2" : "sse2");
    }
}

} // namespace

namespace {

// Pooling (flip/pooling.h): the one-pass weighted percentiles equal one scan per fraction, and the
// radix sort equals std::sort.
TEST(Pooling, OnePassPercentilesEqualOneScanEach) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<float> v(size_t(1 + rng() % 3000));
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (auto& x : v) x = trial % 5 == 0 ? 0.0f : (rng() % 4 == 0 ? 0.5f : u(rng)); // zeros, ties
        std::vector<float> sorted = v;
        flip::radix_sort_nonnegative(sorted);
        std::vector<float> expected = v;
        std::sort(expected.begin(), expected.end());
        ASSERT_TRUE(same_bits(sorted.data(), expected.data(), v.size()));
        float total = 0.0f;
        for (float x : v) total += x;
        const auto all = flip::weighted_percentiles_sorted<3>(sorted, total, {0.5f, 0.25f, 0.75f});
        EXPECT_EQ(all[0], flip::weighted_percentile_sorted(sorted, total, 0.5f));
        EXPECT_EQ(all[1], flip::weighted_percentile_sorted(sorted, total, 0.25f));
        EXPECT_EQ(all[2], flip::weighted_percentile_sorted(sorted, total, 0.75f));
    }
}

} // namespace
} // namespace test_flip_kernels
