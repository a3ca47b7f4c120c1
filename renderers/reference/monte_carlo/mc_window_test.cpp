// The windowed environment strategy (mc_window.h) against its contract: the window's pdf integrates to 1
// over the sphere, a sample's returned pdf is the pdf the estimator evaluates for its direction, and the
// pixel's view cone is the normal it sees.
#include "renderers/reference/monte_carlo/mc_window.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace iblcheck;
using namespace iblcheck::reference;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace mc_window_test {

namespace {
struct Fixture {
    Scene scene = build_scene("sphere", OptionMap{});
    Environment env = load_environment("sky_sun");
    EnvDistribution dist{env};
    int W = scene.width, H = scene.height;
};
} // namespace

TEST(McWindow, ViewConeOfAnInteriorPixelIsItsNormal) {
    Fixture f;
    const int x = f.W / 2 + 10, y = f.H / 2 - 7;
    PixelCone cone;
    ASSERT_TRUE(pixel_view_cone(f.scene, f.W, f.H, x, y, 0, cone));
    Vec3f o, d;
    camera_ray(f.scene, f.W, f.H, x + 0.5, y + 0.5, o, d);
    const Hit h = intersect(f.scene, o, d);
    ASSERT_TRUE(h.hit);
    EXPECT_GT(dot(cone.n0, Vec3d{h.normal.x, h.normal.y, h.normal.z}), std::cos(cone.spread));
    EXPECT_LT(cone.spread, 0.35); // fully covered: only the pixel's own spread (+0.01)
    EXPECT_GT(cone.spread, 0.01);
    // A pixel the grid misses entirely: the centre ray's closest approach, a grazing normal (n₀ ⟂ v₀).
    PixelCone corner;
    ASSERT_TRUE(pixel_view_cone(f.scene, f.W, f.H, 0, 0, 0, corner));
    EXPECT_NEAR(dot(corner.n0, corner.v0), 0.0, 1e-9);
    EXPECT_GE(corner.spread, 0.35);
}

// For the two specular windows and a dielectric (diffuse + specular terms): Σ_c factor_c · W_c = 1, so the
// mixture (1 − ε)·window + ε·global integrates to 1; every sample's pdf equals win.pdf() of its direction.
TEST(McWindow, WindowPdfIsNormalisedAndMatchesItsSamples) {
    Fixture f;
    for (const bool lobe : {false, true})
        for (const double metallic : {0.0, 1.0}) {
            Material mat;
            mat.roughness = 0.3f, mat.metallic = float(metallic);
            const MatConst M = mat_const(mat, McLobes::all);
            EnvWindow win;
            build_window(f.scene, f.W, f.H, f.W / 2 + 20, f.H / 2 + 5, 0, M, f.dist, lobe, win);
            ASSERT_TRUE(win.valid);
            double mass = 0;
            for (int c = 0; c < f.dist.cells_x() * f.dist.cells_y(); ++c) mass += win.factor[size_t(c)] * f.dist.cell_mass(c);
            EXPECT_NEAR(mass, 1.0, 1e-9) << "lobe " << lobe << " metallic " << metallic;
            for (int k = 0; k < 2000; ++k) {
                double e0, e1, d[3], u, v;
                sobol_owen_2d(uint32_t(k), 3, e0, e1);
                const double p = sample_env_window(f.dist, win, e0, e1, d, u, v);
                ASSERT_GT(p, 0);
                double du, dv;
                f.dist.to_uv(d, du, dv);
                EXPECT_NEAR(win.pdf(f.dist, du, dv, f.dist.pdf_uv(du, dv)) / p, 1.0, 1e-6) << k;
            }
        }
}
} // namespace mc_window_test
