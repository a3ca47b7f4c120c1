// The quadrature rule for one shading point: white furnace identities, constant-environment closed
// forms, a small bright source, and the error indicator against a much finer solution.
#include "renderers/reference/quadrature/lobe_quadrature.h"

#include <gtest/gtest.h>

#include <vector>

using namespace iblcheck;
using namespace iblcheck::truth;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace lobe_quadrature_test {

namespace {
MaterialLobe metal(double roughness, double f0 = 1.0) {
    Material m;
    m.roughness = float(roughness), m.metallic = 1, m.base_color = {float(f0), float(f0), float(f0)};
    return material_lobe(m, Lobes::all);
}

// E(μ = 1) = ∫ D V F (n·l) dl with F0 = 1 at normal incidence, independently as a 1D integral over θ_h
// (the lobe is symmetric about n: θ_l = 2θ_h, dω_l = 4 (v·h) dω_h), Gauss–Legendre on a ξ = tan²θ_h/α²
// mapping that follows the lobe.
double albedo_normal_incidence(double alpha) {
    const int n = 4000;
    double sum = 0;
    // θ_h = atan(α·tan(π t / 2)·...) : substitute s = atan(tan θ_h / α) ∈ [0, atan(1/α)] (θ_h ≤ π/4).
    const double smax = std::atan(1.0 / alpha);
    for (int k = 0; k < n; ++k) {
        const double s = (k + 0.5) / n * smax, ds = smax / n;
        const double th = std::atan(alpha * std::tan(s));
        const double dth = alpha / (std::cos(s) * std::cos(s)) / (1 + alpha * alpha * std::tan(s) * std::tan(s)) * ds;
        const double nl = std::cos(2 * th);
        sum += model::d_ggx(std::cos(th), alpha) * model::v_smith_ggx_correlated(1.0, nl, alpha) * nl * 4 * std::cos(th) * 2 *
               kPi * std::sin(th) * dth;
    }
    return sum;
}

double quad(const EnvPyramid& env, const MaterialLobe& L, V3 n, V3 v, double tol, ShadeStats* st = nullptr, double kappa = 0.5) {
    QuadratureParams p;
    p.tolerance = tol;
    p.kappa = kappa;
    double rgb[3] = {0, 0, 0};
    shade(env, L, shading_point(n, v, L), p, rgb, st);
    return rgb[1];
}
} // namespace

TEST(LobeQuadrature, WhiteFurnaceKnownAlbedos) {
    EnvPyramid env(load_environment("constant:1"));
    const V3 n{0, 0, 1};
    // material_model.h: GGX + height-correlated Smith, F0 = 1, normal incidence.
    EXPECT_NEAR(quad(env, metal(0.5), n, n, 1e-5), 0.91581, 5e-5);
    EXPECT_NEAR(quad(env, metal(1.0), n, n, 1e-5), 1 - std::log(2.0), 5e-5);
    EXPECT_NEAR(albedo_normal_incidence(0.25), 0.91581, 5e-5);
    EXPECT_NEAR(albedo_normal_incidence(1.0), 1 - std::log(2.0), 5e-5);
    // Narrow lobes (the guard's job): r = 0.1 (α = 0.01) and r = 0.05 (the temporal suite's bumpy sphere).
    for (double r : {0.05, 0.1, 0.2, 0.3}) {
        ShadeStats st;
        const double got = quad(env, metal(r), n, n, 1e-4, &st);
        EXPECT_NEAR(got / albedo_normal_incidence(r * r), 1.0, 3e-4) << "roughness " << r;
        std::printf("furnace r=%.2f: quadrature %.6f, 1D integral %.6f, %ld evaluations\n", r, got,
                    albedo_normal_incidence(r * r), st.evaluations);
    }
}

// Constant environment: a white Lambert sphere reflects exactly its albedo; a dielectric is 1 + the
// F0 = 0.04 specular albedo; an F0 = 0 "metal" reflects nothing at normal incidence... and a mirror is F.
TEST(LobeQuadrature, ConstantEnvironmentClosedForms) {
    EnvPyramid env(load_environment("constant:0.5"));
    Material m;
    m.base_color = {0.8f, 0.8f, 0.8f};
    const MaterialLobe lambert = material_lobe(m, Lobes::diffuse);
    for (V3 n : {V3{0, 0, 1}, normalize(V3{0.3, -0.7, 0.2}), V3{0, 1, 0}})
        EXPECT_NEAR(quad(env, lambert, n, V3{0, 0, 1}, 1e-5), 0.4, 1e-5);
    m.roughness = 0;
    m.metallic = 1;
    const MaterialLobe mirror = material_lobe(m, Lobes::all);
    const V3 n = normalize(V3{0.5, 0.2, 0.6});
    const double nv = n.z;
    EXPECT_NEAR(quad(env, mirror, n, V3{0, 0, 1}, 1e-5), 0.5 * model::f_schlick(0.8, nv), 1e-7);
}

// A bright patch (1e4, 3x3 texels) in a black environment, seen by a rough and by a narrow lobe: the
// quadrature against a brute-force 48x48 midpoint rule per texel of bilinear radiance × f·cos over the
// texels the bilinear patch reaches.
TEST(LobeQuadrature, SmallBrightSourceMatchesBruteForce) {
    Environment e;
    e.spec = "patch";
    e.equirect = cv::Mat(256, 512, CV_32FC3, cv::Scalar(0, 0, 0));
    for (int j = 100; j < 103; ++j)
        for (int i = 300; i < 303; ++i) e.equirect.at<cv::Vec3f>(j, i) = {1e4f, 1e4f, 1e4f};
    EnvPyramid env(e);
    const V3 v{0, 0, 1};
    for (double rough : {0.6, 0.15}) {
        const MaterialLobe L = metal(rough);
        // The patch's centre pixel direction, offset so that the peak is not exactly on it.
        V3 pc;
        double om, rgb[3];
        env.subcell(301, 101, 1, 0, 0, pc, om, rgb);
        const V3 n = normalize(normalize(pc + V3{0.01, 0.004, 0}) + v);
        const ShadingPoint sp = shading_point(n, v, L);
        double brute = 0;
        const int k = 48;
        for (int j = 99; j < 104; ++j)
            for (int i = 299; i < 304; ++i)
                for (int b = 0; b < k; ++b)
                    for (int a = 0; a < k; ++a) {
                        V3 d;
                        double o, Lr[3], f[3];
                        env.subcell(i, j, k, a, b, d, o, Lr);
                        fcos(L, sp, d, f);
                        brute += f[1] * Lr[1] * o;
                    }
        const double got = quad(env, L, n, v, 1e-5);
        std::printf("patch, roughness %.2f: quadrature %.6g, brute force %.6g\n", rough, got, brute);
        EXPECT_NEAR(got / brute, 1.0, 3e-4) << "roughness " << rough;
    }
}

// The error indicator (Σ |fine − coarse| over the final cells) bounds the error against a much finer
// solution, on the studio environment for lobes from mirror-like to rough at several angles.
TEST(LobeQuadrature, IndicatorBoundsErrorAgainstFinerSolution) {
    Environment e = load_environment("studio");
    EnvPyramid env(e);
    int checked = 0;
    double worst_ratio = 0;
    for (double r : {0.05, 0.1, 0.3, 0.7, 1.0})
        for (V3 n : {V3{0, 0, 1}, normalize(V3{0.6, 0.3, 0.5}), normalize(V3{-0.2, 0.9, 0.25}), normalize(V3{0.95, 0, 0.1})}) {
            const MaterialLobe L = metal(r, 0.9);
            ShadeStats coarse;
            const double a = quad(env, L, n, V3{0, 0, 1}, 1e-3, &coarse);
            const double truth = quad(env, L, n, V3{0, 0, 1}, 1e-6, nullptr, 0.125);
            const double err = std::fabs(a - truth);
            EXPECT_LE(err, coarse.error + 1e-9 * truth) << "roughness " << r << " n=(" << n.x << "," << n.y << "," << n.z << ")";
            EXPECT_LE(err, 1e-3 * truth);
            worst_ratio = std::max(worst_ratio, err / std::max(coarse.error, 1e-30));
            ++checked;
        }
    std::printf("%d shading points: largest error / indicator %.3f\n", checked, worst_ratio);
}
} // namespace lobe_quadrature_test
