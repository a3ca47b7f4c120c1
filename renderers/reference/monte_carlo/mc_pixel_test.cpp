// One pixel of the Monte Carlo integrator (mc_pixel.h): the sphere culling is conservative and the
// candidate intersection is scene.cpp's; a pixel's coverage is the fraction of its positions that hit.
#include "renderers/reference/monte_carlo/mc_pixel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

using namespace iblcheck;
using namespace iblcheck::reference;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace mc_pixel_test {

// Every sub-pixel ray of the roughness sweep (4x4 per pixel) that hits a sphere hits one of the pixel's
// candidates, and intersect_candidates finds the same sphere and normal as intersect().
TEST(McPixel, CandidatesAreConservativeAndIntersectAsTheScene) {
    const Scene scene = build_scene("roughness_sweep", OptionMap{});
    const int W = scene.width, H = scene.height;
    std::vector<int> cand;
    long hits = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            pixel_candidates(scene, W, H, x, y, cand);
            for (int k = 0; k < 16; ++k) {
                Vec3f o, d;
                camera_ray(scene, W, H, x + (k % 4 + 0.5) / 4, y + (k / 4 + 0.5) / 4, o, d);
                const Hit h = intersect(scene, o, d);
                int sphere;
                Vec3d n;
                const bool hit = intersect_candidates(scene, cand, o, d, sphere, n);
                ASSERT_EQ(hit, h.hit) << x << "," << y;
                if (!h.hit) continue;
                ++hits;
                ASSERT_NE(std::find(cand.begin(), cand.end(), h.sphere), cand.end()) << x << "," << y;
                EXPECT_EQ(sphere, h.sphere);
                EXPECT_NEAR(n.x, h.normal.x, 1e-6);
                EXPECT_NEAR(n.y, h.normal.y, 1e-6);
                EXPECT_NEAR(n.z, h.normal.z, 1e-6);
            }
        }
    EXPECT_GT(hits, 0);
}

namespace {
// One pixel's context: the scene and environment named, every sphere's material, all lobes, the window.
struct Pixels {
    Scene scene;
    int W, H;
    Environment env;
    EnvDistribution dist;
    cv::Mat equirect;
    EnvImage img;
    Shader shader;
    std::vector<MatConst> mats;
    PixelContext ctx;
    Pixels(const std::string& scene_name, const std::string& env_name)
        : scene(build_scene(scene_name, OptionMap{})), W(scene.width), H(scene.height), env(load_environment(env_name)),
          dist(env), equirect(env.equirect.clone()), img(equirect), shader{img, dist, McLobes::all, true, true},
          mats(materials(scene)), ctx{scene, W, H, shader, mats, false} {}
    Pixels(const Pixels&) = delete; // the context refers to the members
    static std::vector<MatConst> materials(const Scene& s) {
        std::vector<MatConst> m;
        for (const Sphere& sp : s.spheres) m.push_back(mat_const(sp.material, McLobes::all));
        return m;
    }
};
} // namespace

TEST(McPixel, CoverageIsTheFractionOfPositionsThatHit) {
    const Pixels px("sphere", "constant:1");
    PixelScratch scratch;
    std::vector<int>& cand = scratch.cand;
    long fetches = 0;
    pixel_candidates(px.scene, px.W, px.H, px.W / 2, px.H / 2, cand);
    const PixelOut inside = render_pixel(px.ctx, px.W / 2, px.H / 2, 16, 2, 1, 2, scratch, fetches);
    EXPECT_EQ(inside.coverage, 1.0);
    EXPECT_GT(inside.rgb[0], 0);
    EXPECT_GE(inside.lum_var, 0);
    EXPECT_GT(fetches, 0);
    pixel_candidates(px.scene, px.W, px.H, 0, 0, cand);
    const PixelOut corner = render_pixel(px.ctx, 0, 0, 16, 2, 1, 2, scratch, fetches);
    EXPECT_EQ(corner.coverage, 0.0);
    EXPECT_EQ(corner.rgb[0], 0.0);
    // A silhouette pixel: some positions hit. Find one along the centre row.
    for (int x = 0; x < px.W / 2; ++x) {
        pixel_candidates(px.scene, px.W, px.H, x, px.H / 2, cand);
        const PixelOut p = render_pixel(px.ctx, x, px.H / 2, 64, 1, 1, 2, scratch, fetches);
        if (p.coverage == 0) continue;
        EXPECT_LT(p.coverage, 1.0) << "the first pixel that hits is on the silhouette";
        EXPECT_EQ(std::fmod(p.coverage * 64, 1.0), 0.0);
        break;
    }
}

// A worker's scratch is reused from pixel to pixel: a pixel renders the same bits after any other as
// with fresh scratch, whatever window the last pixel left there (another sphere's, another material's).
TEST(McPixel, ReusedScratchRendersEachPixelAsFreshScratchDoes) {
    const Pixels px("sphere_field", "sky_sun");
    PixelScratch reused;
    std::set<int> spheres;
    int compared = 0;
    for (int y = 0; y < px.H; y += 7)
        for (int x = 0; x < px.W; x += 5) {
            long f1 = 0, f2 = 0;
            pixel_candidates(px.scene, px.W, px.H, x, y, reused.cand);
            if (reused.cand.empty()) continue;
            PixelScratch fresh;
            fresh.cand = reused.cand;
            const PixelOut a = render_pixel(px.ctx, x, y, 8, 2, 3, uint32_t(x * 977 + y), reused, f1);
            const PixelOut b = render_pixel(px.ctx, x, y, 8, 2, 3, uint32_t(x * 977 + y), fresh, f2);
            ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << x << "," << y;
            ASSERT_EQ(f1, f2);
            spheres.insert(reused.cand[0]);
            ++compared;
        }
    EXPECT_GT(compared, 50);
    EXPECT_GT(spheres.size(), 4u) << "pixels of several spheres, one after another";
}
} // namespace mc_pixel_test
