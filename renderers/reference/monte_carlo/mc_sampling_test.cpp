// The Monte Carlo integrator's sampling functions (mc_sampling.h), each against its contract.
#include "renderers/reference/monte_carlo/mc_sampling.h"

#include <gtest/gtest.h>

#include <cmath>

#include "renderers/reference/monte_carlo/env_distribution.h"

using namespace iblcheck;
using namespace iblcheck::reference;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace mc_sampling_test {

namespace {
constexpr double kPi = model::kPi;

double length(Vec3d v) { return std::sqrt(dot(v, v)); }
} // namespace

// Sobol dimension 1 is its definition, a direction number per set bit of the index: the first points
// (0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8), every single bit, and random indices against the loop over bits.
TEST(McSampling, SobolDimensionOneIsTheXorOfItsDirectionNumbers) {
    auto by_bits = [](uint32_t index) {
        uint32_t v = 1u << 31, r = 0;
        for (; index; index >>= 1, v ^= v >> 1)
            if (index & 1) r ^= v;
        return r;
    };
    const double first[8] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
    for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(sobol_dim1(i) / 4294967296.0, first[i]) << i;
    for (int k = 0; k < 32; ++k) EXPECT_EQ(sobol_dim1(1u << k), by_bits(1u << k)) << "bit " << k;
    EXPECT_EQ(sobol_dim1(0xFFFFFFFFu), by_bits(0xFFFFFFFFu));
    uint32_t index = 12345;
    for (int n = 0; n < 100000; ++n) {
        index = hash_u32(index + 1);
        ASSERT_EQ(sobol_dim1(index), by_bits(index)) << index;
    }
}

TEST(McSampling, ShadingFrameIsOrthonormalAndRoundTrips) {
    for (const Vec3d n : {Vec3d{0, 0, 1}, Vec3d{0, 0, -1}, normalize(Vec3d{1, 2, 3}), normalize(Vec3d{-0.3, 0.9, -0.1})}) {
        const ShadingFrame f(n);
        EXPECT_NEAR(length(f.t), 1, 1e-12);
        EXPECT_NEAR(length(f.b), 1, 1e-12);
        EXPECT_NEAR(dot(f.t, f.b), 0, 1e-12);
        EXPECT_NEAR(dot(f.t, f.n), 0, 1e-12);
        EXPECT_NEAR(dot(f.b, f.n), 0, 1e-12);
        const Vec3d w = normalize(Vec3d{0.2, -0.7, 0.4});
        const Vec3d back = f.to_world(f.to_local(w));
        EXPECT_NEAR(length(back - w), 0, 1e-12);
        EXPECT_NEAR(f.to_local(n).z, 1, 1e-12); // n is local +z
    }
}

// Visible normals: h in the upper hemisphere and facing v; at normal incidence pdf(h) = D(h)·cos θ_h, so
// E[cos θ_h / pdf(h)] = ∫ cos θ_h dω_h = π.
TEST(McSampling, GgxVndfSamplesVisibleNormalsWithItsPdf) {
    const double alpha = 0.5;
    const Vec3d oblique = normalize(Vec3d{0.8, 0.1, 0.3});
    double sum = 0;
    const int n = 1 << 16;
    for (int k = 0; k < n; ++k) {
        double u0, u1;
        sobol_owen_2d(uint32_t(k), 17, u0, u1);
        const Vec3d h = sample_ggx_vndf(Vec3d{0, 0, 1}, alpha, u0, u1);
        EXPECT_NEAR(length(h), 1, 1e-12);
        ASSERT_GE(h.z, 0);
        sum += h.z / (model::d_ggx(h.z, alpha) * h.z);
        const Vec3d ho = sample_ggx_vndf(oblique, alpha, u0, u1);
        EXPECT_GE(dot(ho, oblique), -1e-12) << "a visible normal faces the viewer";
        const Vec3d l = reflect_about(oblique, ho);
        EXPECT_NEAR(length(l), 1, 1e-12);
        EXPECT_NEAR(dot(l, ho), dot(oblique, ho), 1e-12); // the mirror of v about h
    }
    EXPECT_NEAR(sum / n / kPi, 1, 2e-3);
    // Near-zero roughness: h is the normal.
    const Vec3d h = sample_ggx_vndf(oblique, 1e-6, 0.3, 0.7);
    EXPECT_NEAR(h.z, 1, 1e-9);
}

// pdf = cos θ/π: E[1] = 1 trivially, so check a moment, E[cos θ] = 2/3, and the unit length.
TEST(McSampling, CosineHemisphereHasCosineDensity) {
    double sum = 0;
    const int n = 1 << 14;
    for (int k = 0; k < n; ++k) {
        double u0, u1;
        sobol_owen_2d(uint32_t(k), 5, u0, u1);
        const Vec3d l = sample_cosine_hemisphere(u0, u1);
        EXPECT_NEAR(length(l), 1, 1e-12);
        ASSERT_GE(l.z, 0);
        sum += l.z;
    }
    EXPECT_NEAR(sum / n, 2.0 / 3.0, 1e-4);
}

// The specular lobe is chosen with probability p_s and the remapped number is uniform in [0,1) given the
// choice: an evenly spaced input gives evenly spaced outputs within each lobe.
TEST(McSampling, SelectLobeKeepsEachLobeStratified) {
    const double p_s = 0.3;
    const int n = 1000;
    int spec = 0;
    double spec_sum = 0, diff_sum = 0;
    for (int k = 0; k < n; ++k) {
        double u = (k + 0.5) / n;
        const bool s = select_lobe(p_s, u);
        ASSERT_GE(u, 0);
        ASSERT_LT(u, 1);
        (s ? spec_sum : diff_sum) += u;
        spec += s;
    }
    EXPECT_EQ(spec, 300);
    EXPECT_NEAR(spec_sum / spec, 0.5, 1e-12);
    EXPECT_NEAR(diff_sum / (n - spec), 0.5, 1e-12);
    double u = 0.9999999999999999; // never rescaled to 1
    EXPECT_FALSE(select_lobe(0.5, u));
    EXPECT_LT(u, 1.0);
    u = 0.25;
    EXPECT_TRUE(select_lobe(1.0, u)); // specular only: p_s = 1
}

TEST(McSampling, MisWeightsOfTheTwoStrategiesSumToOne) {
    for (const bool power : {true, false})
        for (const double pb : {1e-3, 0.2, 1.0, 40.0})
            for (const double pe : {1e-4, 0.5, 3.0, 1e4}) {
                const double wb = mis_weight_brdf_sample(pb, pe, power), we = mis_weight_env_sample(pe, pb, power);
                EXPECT_NEAR(wb + we, 1, 1e-12) << pb << " " << pe;
                EXPECT_GE(wb, 0);
                EXPECT_GE(we, 0);
            }
    EXPECT_DOUBLE_EQ(mis_weight_brdf_sample(1, 2, true), 0.2); // 1/(1+4)
    EXPECT_DOUBLE_EQ(mis_weight_brdf_sample(1, 3, false), 0.25);
}
} // namespace mc_sampling_test
