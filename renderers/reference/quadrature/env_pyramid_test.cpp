// EnvPyramid: exact texel solid angles and integrals of the bilinear filter, sums over levels,
// centroids, rotation, sub-texel cells and radiance ranges.
#include "renderers/reference/quadrature/env_pyramid.h"

#include <gtest/gtest.h>

#include <random>

using namespace iblcheck;
using namespace iblcheck::truth;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace env_pyramid_test {

namespace {
Environment random_env(int W, int H, unsigned seed) {
    Environment e;
    e.spec = "random";
    e.equirect = cv::Mat(H, W, CV_32FC3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 4.0f);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) e.equirect.at<cv::Vec3f>(j, i) = {u(rng), u(rng), u(rng)};
    return e;
}
V3 dir_of(double phi, double z) {
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    return {s * std::sin(phi), z, -s * std::cos(phi)};
}
} // namespace

TEST(EnvPyramid, TexelSolidAnglesAreExact) {
    Environment e = random_env(64, 32, 1);
    EnvPyramid p(e);
    double sum = 0;
    for (int j = 0; j < 32; ++j) {
        EXPECT_NEAR(p.texel_solid_angle(j), 2 * kPi / 64 * (std::cos(j * kPi / 32) - std::cos((j + 1) * kPi / 32)), 1e-15);
        sum += 64 * p.texel_solid_angle(j);
    }
    EXPECT_NEAR(sum, 4 * kPi, 1e-12);
}

// Each level-0 cell holds ∫ L dω of environment.h's bilinear filter over the texel: checked against a
// 96x96 midpoint rule in (φ, cos θ) of bilinear_equirect per texel (that rule is accurate to ~1e-5 here).
TEST(EnvPyramid, TexelIntegralsMatchTheBilinearFilter) {
    const int W = 16, H = 8;
    Environment e = random_env(W, H, 2);
    EnvPyramid p(e);
    const int n = 96;
    double worst = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const double z0 = std::cos(j * kPi / H), z1 = std::cos((j + 1) * kPi / H);
            double acc[3] = {0, 0, 0};
            for (int b = 0; b < n; ++b)
                for (int a = 0; a < n; ++a) {
                    const double u = (i + (a + 0.5) / n) / W, z = z0 + (z1 - z0) * (b + 0.5) / n;
                    double rgb[3];
                    bilinear_equirect(e.equirect.ptr<float>(0), W, H, size_t(W) * 3, u, std::acos(z) / kPi, rgb);
                    for (int q = 0; q < 3; ++q) acc[q] += rgb[q];
                }
            const double omega = 2 * kPi / W * (z0 - z1) / (double(n) * n);
            for (int q = 0; q < 3; ++q) {
                const double rel = std::fabs(p.cell(0, i, j).L[q] / (acc[q] * omega) - 1);
                worst = std::max(worst, rel);
                ASSERT_LT(rel, 2e-4) << "texel " << i << "," << j;
            }
        }
    std::printf("texel integrals vs a 96x96 midpoint rule: worst relative difference %.2e\n", worst);
}

TEST(EnvPyramid, LevelsSumExactlyAndCentroidsFindBrightTexels) {
    Environment e(random_env(64, 32, 3));
    e.equirect.at<cv::Vec3f>(9, 37) = {5e4f, 5e4f, 5e4f}; // a "sun" texel
    EnvPyramid p(e);
    double l0[3] = {0, 0, 0};
    for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 64; ++i)
            for (int q = 0; q < 3; ++q) l0[q] += p.cell(0, i, j).L[q];
    for (int k = 1; k < p.levels(); ++k) {
        double s[3] = {0, 0, 0};
        for (int j = 0; j < p.height(k); ++j)
            for (int i = 0; i < p.width(k); ++i)
                for (int q = 0; q < 3; ++q) s[q] += p.cell(k, i, j).L[q];
        for (int q = 0; q < 3; ++q) EXPECT_NEAR(s[q] / l0[q], 1.0, 1e-6) << "level " << k;
    }
    EXPECT_EQ(p.width(p.top_level()), 8);
    // The centroid of the level-3 cell holding the sun texel points (almost) at the sun texel.
    const EnvCell& c = p.cell(3, 37 >> 3, 9 >> 3);
    const V3 sun = dir_of((37.5 / 64 - 0.5) * 2 * kPi, std::cos(9.5 * kPi / 32));
    EXPECT_GT(dot(V3{c.c[0], c.c[1], c.c[2]}, sun), std::cos(0.02));
    EXPECT_LT(dot(V3{c.g[0], c.g[1], c.g[2]}, sun), std::cos(0.05)); // unlike its geometric centre
}

TEST(EnvPyramid, RotationMatchesEnvironmentLookup) {
    Environment e = load_environment("sky_sun");
    e.rotation_deg = 40;
    EnvPyramid p(e);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int k = 0; k < 200; ++k) {
        V3 d = normalize(V3{u(rng), u(rng), u(rng)});
        float df[3] = {float(d.x), float(d.y), float(d.z)}, ref[3];
        sample_bilinear(e, df, ref);
        double got[3];
        p.radiance(d, got);
        for (int q = 0; q < 3; ++q) EXPECT_NEAR(got[q], ref[q], 1e-3 * (1 + ref[q]));
    }
}

TEST(EnvPyramid, SubcellsPartitionTheTexel) {
    Environment e = random_env(32, 16, 5);
    EnvPyramid p(e);
    for (int j : {0, 5, 15}) {
        double omega_sum = 0, acc[3] = {0, 0, 0};
        const int n = 64;
        for (int b = 0; b < n; ++b)
            for (int a = 0; a < n; ++a) {
                V3 d;
                double om, L[3];
                p.subcell(7, j, n, a, b, d, om, L);
                omega_sum += om;
                for (int q = 0; q < 3; ++q) acc[q] += L[q] * om;
                EXPECT_NEAR(dot(d, d), 1.0, 1e-12);
            }
        EXPECT_NEAR(omega_sum / p.texel_solid_angle(j), 1.0, 1e-12);
        for (int q = 0; q < 3; ++q) EXPECT_NEAR(acc[q] / p.cell(0, 7, j).L[q], 1.0, 2e-4) << "row " << j;
    }
}

// The 2x2 Gauss rule of a sub-texel cell (its fast path reads the four texels of the cell's quadrant
// once): the same nodes and weights as the bilinear filter read through environment.h at each node, and
// Σ over the cells of a split texel = the texel's exact integral (the rule is exact for the bilinear
// radiance in u and near-exact in θ, where sin θ varies). Texels on the seam (i = 0, u wraps) and the
// poles (v clamps) included.
TEST(EnvPyramid, SubcellGaussRuleMatchesTheFilterAndSumsToTheTexel) {
    for (int W : {32, 128}) { // 32: the libm path; 128: texels small enough for the angle-sum series
        const int H = W / 2;
        Environment e = random_env(W, H, 9);
        EnvPyramid p(e);
        for (auto [i, j] : {std::pair{0, 0}, {W - 1, H - 1}, {7, 5}, {W / 2, H / 2}})
            for (int n : {2, 4, 8}) {
                double sum[3] = {0, 0, 0};
                for (int b = 0; b < n; ++b)
                    for (int a = 0; a < n; ++a) {
                        V3 dir[4];
                        double wL[4][3];
                        p.subcell_gauss(i, j, n, a, b, dir, wL);
                        const double g = 0.5 / std::sqrt(3.0), w0 = 0.25 * (2 * kPi / (double(W) * n)) * (kPi / (double(H) * n));
                        for (int k = 0; k < 4; ++k) {
                            const double fu = (a + 0.5 + ((k & 1) ? g : -g)) / n, ft = (b + 0.5 + ((k >> 1) ? g : -g)) / n;
                            double st, L[3];
                            const V3 d = p.dir_in_texel(i, fu, j, ft, &st);
                            bilinear_equirect(e.equirect.ptr<float>(0), W, H, size_t(W) * 3, (i + fu) / W, (j + ft) / H, L);
                            EXPECT_NEAR(dot(d, dir[k]), 1.0, 1e-12);
                            for (int q = 0; q < 3; ++q) {
                                EXPECT_NEAR(wL[k][q], w0 * st * L[q], 1e-12 * (1 + std::fabs(w0 * st * L[q])));
                                sum[q] += wL[k][q];
                            }
                        }
                    }
                for (int q = 0; q < 3; ++q) EXPECT_NEAR(sum[q] / p.cell(0, i, j).L[q], 1.0, 1e-3) << i << "," << j << " n=" << n;
            }
    }
}

// radiance_range bounds the bilinear radiance over a cone (random cones and directions inside them).
TEST(EnvPyramid, RadianceRangeBoundsTheCone) {
    Environment e = load_environment("studio");
    e.rotation_deg = 15;
    EnvPyramid p(e);
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-1, 1), r01(0, 1);
    for (int k = 0; k < 300; ++k) {
        const V3 d = normalize(V3{u(rng), u(rng), u(rng)});
        const double rad = 0.002 + 0.3 * r01(rng) * r01(rng);
        double lo[3], hi[3];
        p.radiance_range(d, rad, lo, hi);
        for (int t = 0; t < 20; ++t) {
            V3 q = normalize(V3{u(rng), u(rng), u(rng)});
            q = normalize(d + std::tan(rad) * r01(rng) * normalize(q - dot(q, d) * d));
            double L[3];
            p.radiance(q, L);
            for (int c = 0; c < 3; ++c) {
                ASSERT_GE(L[c], lo[c] - 1e-5) << k;
                ASSERT_LE(L[c], hi[c] + 1e-5) << k;
            }
        }
    }
}

// The per-channel weights (EnvCell::wa): where the colour changes across a cell, each channel's rule has
// that channel's own first moment — the tangent part of Σ_k w_qk·sp_k / L_q is the tangent part of the
// channel's mean direction m_q — with the same four points as the luminance rule. Without the offsets
// (equal weights, the luminance rule for every channel) the moment error is the colour's shift across the
// cell; the test checks both, on cells where the offsets are not clamped (|a|, |b| < 1/4).
TEST(EnvPyramid, ChannelWeightsReproduceEachChannelsMeanDirection) {
    const int W = 64, H = 32;
    Environment e;
    e.spec = "two-colour";
    e.equirect = cv::Mat(H, W, CV_32FC3);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) { // red rises along φ, blue along θ, green flat: three different centroids
            const double phi = 2 * kPi * (i + 0.5) / W, th = kPi * (j + 0.5) / H;
            e.equirect.at<cv::Vec3f>(j, i) = {float(1.2 + std::sin(th)), 0.5f, float(1.1 + std::sin(phi))};
        }
    EnvPyramid p(e);
    int cells = 0;
    double worst_new = 0, worst_old = 0;
    for (int k = 1; k <= 3; ++k)
        for (int j = 0; j < p.height(k); ++j)
            for (int i = 0; i < p.width(k); ++i) {
                const EnvCell& c = p.cell(k, i, j);
                if (c.np != 4) continue;
                const V3 cc{c.c[0], c.c[1], c.c[2]};
                auto tangent = [&](V3 v) { return v - dot(v, cc) * cc; };
                for (int q = 0; q < 3; ++q) {
                    const double a = c.wa[q][0], b = c.wa[q][1];
                    if (std::max(std::fabs(a), std::fabs(b)) > 0.2499) continue;
                    const double w[4] = {0.25 + a, 0.25 - a, 0.25 + b, 0.25 - b};
                    V3 rule{0, 0, 0}, plain{0, 0, 0};
                    for (int s = 0; s < 4; ++s) {
                        const V3 sp{c.sp[s][0], c.sp[s][1], c.sp[s][2]};
                        rule = rule + w[s] * sp, plain = plain + 0.25 * sp;
                    }
                    const V3 want = tangent(V3{c.m[q][0], c.m[q][1], c.m[q][2]});
                    worst_new = std::max(worst_new, std::sqrt(dot(tangent(rule) - want, tangent(rule) - want)) / c.radius);
                    worst_old = std::max(worst_old, std::sqrt(dot(tangent(plain) - want, tangent(plain) - want)) / c.radius);
                    ++cells;
                }
            }
    std::printf("%d cell-channels: moment error / cell radius %.2e with the channel weights, %.2e without\n", cells, worst_new,
                worst_old);
    ASSERT_GT(cells, 300);
    EXPECT_LT(worst_new, 1e-4);
    EXPECT_GT(worst_old, 0.02); // the colour shift the offsets correct is real in this environment
}
} // namespace env_pyramid_test
