// The pixel footprint: exact disc coverage and centroids, the adaptive integral on closed forms, and
// the polar rule at the silhouette.
#include "renderers/reference/quadrature/footprint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace iblcheck::truth;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace footprint_test {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Area and centroid of disc ∩ rectangle by a fine midpoint grid (the independent check).
double brute_area(const Disc& d, double x0, double y0, double x1, double y1, double& mx, double& my, int n = 1200) {
    double a = 0, sx = 0, sy = 0;
    const double dx = (x1 - x0) / n, dy = (y1 - y0) / n;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = x0 + (i + 0.5) * dx, y = y0 + (j + 0.5) * dy;
            if ((x - d.cx) * (x - d.cx) + (y - d.cy) * (y - d.cy) <= d.r * d.r)
                a += dx * dy, sx += x * dx * dy, sy += y * dx * dy;
        }
    mx = a > 0 ? sx / a : 0, my = a > 0 ? sy / a : 0;
    return a;
}
} // namespace

TEST(Footprint, DiscRectAreaAndCentroidAreExact) {
    const Disc d{10.3, 7.6, 5.2};
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 16), s(0.05, 3);
    int partial = 0;
    for (int k = 0; k < 300; ++k) {
        const double x0 = u(rng), y0 = u(rng), w = s(rng), h = s(rng);
        double mx = 0, my = 0, bx, by;
        const double a = disc_rect_area(d, x0, y0, x0 + w, y0 + h, &mx, &my);
        const double b = brute_area(d, x0, y0, x0 + w, y0 + h, bx, by, 600);
        ASSERT_NEAR(a, b, 2e-3 * w * h + 1e-12) << k;
        if (a > 0.05 * w * h && a < 0.95 * w * h) {
            ++partial;
            EXPECT_NEAR(mx, bx, 5e-3 * w);
            EXPECT_NEAR(my, by, 5e-3 * h);
        }
    }
    EXPECT_GT(partial, 20);
    // The whole disc, and a quarter.
    EXPECT_NEAR(disc_rect_area(d, -10, -10, 30, 30), kPi * d.r * d.r, 1e-9);
    EXPECT_NEAR(disc_rect_area(d, d.cx, d.cy, d.cx + 10, d.cy + 10), kPi * d.r * d.r / 4, 1e-9);
}

// The integral of a smooth function of position over pixel ∩ disc, against a fine midpoint grid: in
// the interior, on the silhouette, and for the silhouette's own singularity (a function of
// n·v = √(1 − ρ²/r²), whose derivative is infinite at the rim: the polar rule's case).
TEST(Footprint, IntegralMatchesBruteForceInsideAndOnTheRim) {
    const Disc d{20.5, 20.5, 17.3};
    auto nv = [&](double x, double y) {
        const double r2 = ((x - d.cx) * (x - d.cx) + (y - d.cy) * (y - d.cy)) / (d.r * d.r);
        return std::sqrt(std::max(0.0, 1 - r2));
    };
    PointShader g = [&](double x, double y, double out[3]) {
        const double c = nv(x, y);
        out[0] = 1 + 2 * std::pow(1 - c, 5), out[1] = 0.5 + std::sin(0.3 * x) * y / 40, out[2] = std::sqrt(c);
    };
    FootprintParams p;
    p.tolerance = 1e-6;
    double worst = 0;
    for (auto [px, py] : {std::pair{20, 20}, {33, 15}, {37, 20}, {6, 10}, {20, 3}, {8, 8}, {32, 32}}) {
        const PixelIntegral pi = integrate_pixel(d, px, py, g, nullptr, p);
        EXPECT_NEAR(pi.coverage, disc_rect_area(d, px, py, px + 1, py + 1), 1e-12);
        ASSERT_GT(pi.coverage, 0) << "pixel " << px << "," << py << " misses the disc";
        // Reference: 4000² midpoint grid of the integrand inside the disc.
        const int n = 4000;
        double ref[3] = {0, 0, 0};
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x = px + (i + 0.5) / n, y = py + (j + 0.5) / n;
                if ((x - d.cx) * (x - d.cx) + (y - d.cy) * (y - d.cy) > d.r * d.r) continue;
                double v[3];
                g(x, y, v);
                for (int q = 0; q < 3; ++q) ref[q] += v[q] / (double(n) * n);
            }
        // The grid's own error at the silhouette is ~1e-5 of the pixel (checked at pixel 6,10 against a
        // 200x200 Gauss–Legendre product rule with the rim's square root substituted away: 1.1359990 vs the
        // grid's 1.1360006). Before the polar rule took 5 points in ψ, pixel 6,10 settled 5.7e-4 of its
        // value off at any tolerance (a corner sliver, EverySilhouettePixelMatchesAnIndependentPolarIntegral).
        // Channel 2 (√(n·v), a stronger singularity than any BRDF's: shading is smooth in n·v) is ~1e-5
        // off on the rim; channels 0 and 1 agree with the grid to its own error.
        const bool rim = pi.coverage < 1;
        for (int q = 0; q < 3; ++q) {
            const double tol = !rim ? 3e-5 : q == 2 ? 1e-4 : 2e-5;
            EXPECT_NEAR(pi.rgb[q], ref[q], tol * (1 + std::fabs(ref[q]))) << "pixel " << px << "," << py << " channel " << q;
            worst = std::max(worst, std::fabs(pi.rgb[q] - ref[q]));
        }
    }
    std::printf("footprint integrals vs a 4000x4000 grid: worst difference %.2e\n", worst);
}

// Every pixel the silhouette crosses, for shading n·v (the shape of a BRDF's grazing falloff), against an
// independent integral: 10⁵ rays from the disc's centre across the pixel, each integrated in closed form
// (∫ √(1 − ρ²/r²) ρ dρ = −r²/3 (1 − ρ²/r²)^{3/2}). The pixels where the disc clips only a corner are
// the case the midpoint rule in ψ got wrong at every depth (up to −12 % of such a pixel: its children
// reproduce the same sliver, so the refinement saw no error).
TEST(Footprint, EverySilhouettePixelMatchesAnIndependentPolarIntegral) {
    const Disc d{20.5, 20.5, 17.3};
    PointShader g = [&](double x, double y, double out[3]) {
        const double r2 = ((x - d.cx) * (x - d.cx) + (y - d.cy) * (y - d.cy)) / (d.r * d.r);
        out[0] = out[1] = out[2] = std::sqrt(std::max(0.0, 1 - r2));
    };
    auto independent = [&](int px, int py) {
        const double X0 = px - d.cx, X1 = X0 + 1, Y0 = py - d.cy, Y1 = Y0 + 1, r = d.r;
        const double pc = std::atan2(Y0 + 0.5, X0 + 0.5);
        double lo = 1e9, hi = -1e9;
        for (int k = 0; k < 4; ++k) {
            const double a = std::remainder(std::atan2((k >> 1) ? Y1 : Y0, (k & 1) ? X1 : X0) - pc, 2 * kPi);
            lo = std::min(lo, a), hi = std::max(hi, a);
        }
        auto F = [&](double t) { return -(r * r / 3) * std::pow(std::max(0.0, 1 - t * t / (r * r)), 1.5); };
        const int n = 100000;
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            const double psi = pc + lo + (i + 0.5) * (hi - lo) / n, ux = std::cos(psi), uy = std::sin(psi);
            const double tx0 = X0 / ux, tx1 = X1 / ux, ty0 = Y0 / uy, ty1 = Y1 / uy;
            const double t0 = std::max({0.0, std::min(tx0, tx1), std::min(ty0, ty1)});
            const double t1 = std::min({r, std::max(tx0, tx1), std::max(ty0, ty1)});
            if (t1 > t0) sum += (F(t1) - F(t0)) * (hi - lo) / n;
        }
        return sum;
    };
    FootprintParams p;
    p.tolerance = 1e-5;
    int rim = 0, slivers = 0;
    double worst = 0;
    for (int py = 2; py < 40; ++py)
        for (int px = 2; px < 40; ++px) {
            const double cov = disc_rect_area(d, px, py, px + 1, py + 1);
            if (cov <= 0 || cov >= 1) continue;
            ++rim, slivers += cov < 0.05;
            const double ref = independent(px, py), got = integrate_pixel(d, px, py, g, nullptr, p).rgb[0];
            EXPECT_NEAR(got, ref, 2e-5 * ref + 1e-9) << "pixel " << px << "," << py << " coverage " << cov;
            worst = std::max(worst, std::fabs(got - ref) / ref);
        }
    EXPECT_GT(rim, 100);
    EXPECT_GT(slivers, 5);
    std::printf("%d silhouette pixels (%d slivers under 5 %% coverage): worst relative difference %.2e\n", rim, slivers, worst);
}

// A small bright spot inside a pixel, between the points a few levels of squares would use: the
// variation bound finds it (without it, the 1-vs-4-point indicator can miss it entirely).
TEST(Footprint, VariationBoundFindsASmallBrightSpot) {
    const Disc d{50, 50, 40};
    const double sx = 50.3137, sy = 50.7071, rad = 0.01; // a 0.02 px spot of value 1e4 on 1
    PointShader g = [&](double x, double y, double out[3]) {
        const double in = (x - sx) * (x - sx) + (y - sy) * (y - sy) < rad * rad ? 1e4 : 0.0;
        out[0] = out[1] = out[2] = 1 + in;
    };
    VariationBound b = [&](double x0, double y0, double s) {
        const bool holds = sx + rad > x0 && sx - rad < x0 + s && sy + rad > y0 && sy - rad < y0 + s;
        return holds ? 1e4 : 0.0;
    };
    FootprintParams p;
    p.tolerance = 1e-3;
    p.bound_depth = 12;
    const double expect = 1 + 1e4 * kPi * rad * rad;
    const PixelIntegral with = integrate_pixel(d, 50, 50, g, &b, p);
    EXPECT_NEAR(with.rgb[0] / expect, 1.0, 2e-2);
    const PixelIntegral without = integrate_pixel(d, 50, 50, g, nullptr, p);
    std::printf("spot pixel: exact %.4f, with the bound %.4f (%ld points), without %.4f (%ld points)\n", expect, with.rgb[0],
                with.evaluations, without.rgb[0], without.evaluations);
}
} // namespace footprint_test
