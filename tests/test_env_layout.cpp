// Layouts of the prefiltered radiance (renderers/mobile/env_layout.h; issue 18): the octahedral and
// lat-long mappings round-trip, every border texel continues the map across its seam, the texel
// solid angles cover the sphere, and texel counts per layout. CPU only (the GLSL twin,
// env_layout.glsl, is held to these by the renders in test_mobile_storage_layout). The chain's
// length and each level's roughness (renderers/mobile/mip_chain.h; issue 27).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernel/errors.h"
#include "renderers/mobile/env_layout.h"
#include "renderers/mobile/mip_chain.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_env_layout {

namespace {
constexpr double kPi = 3.14159265358979323846;
// Angle between unit vectors, accurate near 0 too (2·asin of half the chord).
double angle(const Dir& a, const Dir& b) {
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return 2 * std::asin(std::min(1.0, 0.5 * std::sqrt(dx * dx + dy * dy + dz * dz)));
}
Dir random_dir(std::mt19937& rng) {
    std::normal_distribution<double> g;
    Dir d{g(rng), g(rng), g(rng)};
    double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return {d[0] / l, d[1] / l, d[2] / l};
}
} // namespace

TEST(EnvLayout, OctahedralRoundTrip) {
    std::mt19937 rng(18);
    for (int i = 0; i < 20000; ++i) {
        Dir d = random_dir(rng);
        Uv uv = octahedral_encode(d);
        ASSERT_GE(uv[0], 0.0);
        ASSERT_LE(uv[0], 1.0);
        ASSERT_LT(angle(octahedral_decode(uv), d), 1e-12) << d[0] << "," << d[1] << "," << d[2];
    }
    // The centre is +Z, the corners are −Z, the edge midpoints lie on the z = 0 circle... folded:
    // (1, 0.5) is the direction of (0.5, 0) below the horizon.
    EXPECT_LT(angle(octahedral_decode({0.5, 0.5}), {0, 0, 1}), 1e-12);
    for (Uv corner : {Uv{0, 0}, Uv{1, 0}, Uv{0, 1}, Uv{1, 1}}) EXPECT_LT(angle(octahedral_decode(corner), {0, 0, -1}), 1e-12);
    // Each edge folds onto itself about its midpoint.
    EXPECT_LT(angle(octahedral_decode({1, 0.8}), octahedral_decode({1, 0.2})), 1e-12);
    EXPECT_LT(angle(octahedral_decode({0.3, 0}), octahedral_decode({0.7, 0})), 1e-12);
}

TEST(EnvLayout, EquirectRoundTripUsesTheEnvironmentConvention) {
    std::mt19937 rng(5);
    for (int i = 0; i < 20000; ++i) {
        Dir d = random_dir(rng);
        ASSERT_LT(angle(equirect_decode(equirect_encode(d)), d), 1e-12);
    }
    // environment.h: u = 0.5 + atan2(x, −z)/2π, v = acos(y)/π: −Z at the centre, +Y at the top row.
    EXPECT_LT(angle(equirect_decode({0.5, 0.5}), {0, 0, -1}), 1e-12);
    EXPECT_LT(angle(equirect_decode({0.75, 0.5}), {1, 0, 0}), 1e-12);
    EXPECT_LT(angle(equirect_decode({0.3, 0.0}), {0, 1, 0}), 1e-12);
}

TEST(EnvLayout, EveryBorderTexelContinuesTheMapAcrossItsSeam) {
    // A border texel holds the inner texel across the seam; its direction must therefore lie about
    // one step beyond its inner neighbour: no farther than two neighbouring inner texels lie (the
    // map's largest step; a wrong fold puts it up to π away), and not on top of it (at least 0.3
    // of the next step inward; clamping to the edge instead of wrapping puts it at 0).
    for (EnvLayout layout : {EnvLayout::octahedral, EnvLayout::equirect}) {
        const uint32_t w = layout == EnvLayout::octahedral ? 34 : 66, h = 34; // inner 32x32, 64x32
        double pitch = 0;
        for (uint32_t y = 1; y + 1 < h; ++y)
            for (uint32_t x = 1; x + 1 < w; ++x) {
                Dir d = layout_texel_direction(layout, x, y, w, h);
                if (x + 2 < w) pitch = std::max(pitch, angle(d, layout_texel_direction(layout, x + 1, y, w, h)));
                if (y + 2 < h) pitch = std::max(pitch, angle(d, layout_texel_direction(layout, x, y + 1, w, h)));
            }
        double worst = 0, least = 1e9;
        int border = 0;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                if (x > 0 && y > 0 && x + 1 < w && y + 1 < h) continue;
                ++border;
                // Its inner neighbour, one step toward the inside.
                uint32_t ix = std::clamp(x, 1u, w - 2), iy = std::clamp(y, 1u, h - 2);
                Dir inner = layout_texel_direction(layout, ix, iy, w, h);
                double a = angle(layout_texel_direction(layout, x, y, w, h), inner);
                worst = std::max(worst, a);
                bool corner = (x == 0 || x + 1 == w) && (y == 0 || y + 1 == h);
                if (corner) continue;
                uint32_t nx = x == 0 ? 2 : x + 1 == w ? w - 3 : x, ny = y == 0 ? 2 : y + 1 == h ? h - 3 : y;
                double next = angle(inner, layout_texel_direction(layout, nx, ny, w, h));
                least = std::min(least, a / next);
            }
        EXPECT_EQ(border, int(2 * w + 2 * h - 4));
        std::printf("[ border ] %s: worst border step %.4g rad, largest inner step %.4g rad\n",
                    layout == EnvLayout::octahedral ? "octahedral" : "equirect", worst, pitch);
        EXPECT_LE(worst, 1.01 * pitch) << (layout == EnvLayout::octahedral ? "octahedral" : "equirect");
        EXPECT_GT(least, 0.3) << (layout == EnvLayout::octahedral ? "octahedral" : "equirect");
        std::printf("[ border ] smallest border step / next inward step: %.3g\n", least);
    }
    // The wraps themselves, on integer texels of a 4x4 inner map.
    EXPECT_EQ(gutter_source(EnvLayout::octahedral, {-1, 1}, {4, 4}), (std::array<int, 2>{0, 2}));
    EXPECT_EQ(gutter_source(EnvLayout::octahedral, {4, 0}, {4, 4}), (std::array<int, 2>{3, 3}));
    EXPECT_EQ(gutter_source(EnvLayout::octahedral, {-1, -1}, {4, 4}), (std::array<int, 2>{3, 3}));
    EXPECT_EQ(gutter_source(EnvLayout::octahedral, {2, 2}, {4, 4}), (std::array<int, 2>{2, 2}));
    EXPECT_EQ(gutter_source(EnvLayout::equirect, {-1, 2}, {8, 4}), (std::array<int, 2>{7, 2}));
    EXPECT_EQ(gutter_source(EnvLayout::equirect, {1, -1}, {8, 4}), (std::array<int, 2>{5, 0}));
    EXPECT_EQ(gutter_source(EnvLayout::equirect, {8, 4}, {8, 4}), (std::array<int, 2>{4, 3}));
}

TEST(EnvLayout, TexelSolidAnglesCoverTheSphere) {
    // Sum over the inner texels = 4π; lat-long rows agree with the closed form
    // Ω = (2π/nx)(cos θ0 − cos θ1); the octahedral map's largest/smallest texel ratio is that of
    // a cube, 3√3 ≈ 5.2 (centre of an octant face vs its vertex), measured here.
    for (EnvLayout layout : {EnvLayout::octahedral, EnvLayout::equirect}) {
        const uint32_t w = layout == EnvLayout::octahedral ? 34 : 66, h = 34;
        double total = 0, lo = 1e9, hi = 0;
        for (uint32_t y = 1; y + 1 < h; ++y)
            for (uint32_t x = 1; x + 1 < w; ++x) {
                double o = layout_texel_solid_angle(layout, x, y, w, h);
                total += o;
                lo = std::min(lo, o);
                hi = std::max(hi, o);
                if (layout == EnvLayout::equirect) {
                    double t0 = (y - 1) * kPi / (h - 2), t1 = y * kPi / (h - 2);
                    ASSERT_NEAR(o, 2 * kPi / (w - 2) * (std::cos(t0) - std::cos(t1)), 1e-4 * o) << x << "," << y;
                }
            }
        EXPECT_NEAR(total, 4 * kPi, 2e-3 * 4 * kPi) << int(layout);
        if (layout == EnvLayout::octahedral) {
            EXPECT_GT(hi / lo, 3.0);
            EXPECT_LT(hi / lo, 5.3);
        }
    }
}

TEST(EnvLayout, ExtentsTexelCountsAndMipLimits) {
    EXPECT_EQ(layout_extent(EnvLayout::cube, 128).layers, 6u);
    EXPECT_EQ(layout_extent(EnvLayout::octahedral, 128).width, 256u);
    EXPECT_EQ(layout_extent(EnvLayout::equirect, 128).height, 256u);
    EXPECT_EQ(layout_extent(EnvLayout::equirect, 128).width, 512u);
    // 7 levels of a 128 cube: 6·(128² + … + 2²) = 6·21844; octahedral 256² + … + 4² = 87376;
    // lat-long 2·87376.
    EXPECT_EQ(layout_texel_count(EnvLayout::cube, 128, 7), 6u * 21844);
    EXPECT_EQ(layout_texel_count(EnvLayout::octahedral, 128, 7), 87376u);
    EXPECT_EQ(layout_texel_count(EnvLayout::equirect, 128, 7), 2u * 87376);
    EXPECT_NO_THROW(check_layout_mips(EnvLayout::octahedral, 128, 7)); // last level 4x4: 2x2 inside
    EXPECT_THROW(check_layout_mips(EnvLayout::octahedral, 128, 8), UsageError);
    EXPECT_NO_THROW(check_layout_mips(EnvLayout::cube, 128, 8));
    EXPECT_THROW(env_layout_from_option("sphere"), UsageError);
}

TEST(MipChain, Ue4CurveReadsCubemapMaxMipTheLastMipIndex) {
    // UE4 passes CubemapMaxMip = FloorLog2(capture size) = 7 for 128², not the 8 mips: r = 1 is at
    // mip 7 − 1 − 1 = 5 (4×4), mip 0 holds r = 2^(−5/1.2) ≈ 0.0561 (above FilterPS' 0.01 copy
    // threshold, so it is filtered) and r = 0.1 reads lod 1.01. With the mip count (the old slip) r = 1
    // was at mip 6, mip 0 at r = 2^(−6/1.2) = 0.03125 and r = 0.1 read lod 2.01: one level too coarse.
    EXPECT_EQ(cubemap_max_mip(128), 7u);
    EXPECT_EQ(cubemap_max_mip(8), 3u);
    EXPECT_DOUBLE_EQ(chain_level_roughness("ue4", 5, 128, 8), 1.0);
    EXPECT_NEAR(chain_level_roughness("ue4", 4, 128, 8), std::exp2(-1 / 1.2), 1e-12);
    EXPECT_NEAR(chain_level_roughness("ue4", 0, 128, 8), std::exp2(-5 / 1.2), 1e-12);
    EXPECT_NEAR(chain_roughness_lod("ue4", 0.1, 128, 8), 6 - (1 - 1.2 * std::log2(0.1)), 1e-12); // 1.014
    EXPECT_NEAR(chain_roughness_lod("ue4", 1.0, 512, 10), 7.0, 1e-12);
    for (double lod : {0.5, 2.0, 4.25})
        EXPECT_NEAR(chain_roughness_lod("ue4", chain_level_roughness("ue4", lod, 128, 8), 128, 8), lod, 1e-9);
    // Filament and the origin curve: r = 0 at mip 0, r = 1 at the last level, inverse of each other.
    for (const char* curve : {"filament", "origin"}) {
        EXPECT_EQ(chain_level_roughness(curve, 0, 128, 8), 0.0) << curve;
        EXPECT_NEAR(chain_level_roughness(curve, 7, 128, 8), 1.0, 1e-9) << curve;
        EXPECT_NEAR(chain_roughness_lod(curve, chain_level_roughness(curve, 3.5, 128, 8), 128, 8), 3.5, 1e-9) << curve;
    }
}

TEST(MipChain, LengthFollowsTheBaseSizeAndMustReachRoughnessOne) {
    // Default: the whole chain the layout holds, so the roughest level is r = 1 at every size.
    EXPECT_EQ(chain_levels("ue4", EnvLayout::cube, 128, 0), 8u);
    EXPECT_EQ(chain_levels("ue4", EnvLayout::cube, 512, 0), 10u);
    EXPECT_EQ(chain_levels("ue4", EnvLayout::octahedral, 128, 0), 7u); // down to 4×4 (2×2 inside the border)
    EXPECT_EQ(chain_levels("ue4", EnvLayout::equirect, 64, 0), 6u);
    for (uint32_t size : {8u, 16u, 64u, 128u, 256u, 512u, 2048u}) {
        const uint32_t levels = chain_levels("ue4", EnvLayout::cube, size, 0);
        EXPECT_DOUBLE_EQ(chain_level_roughness("ue4", levels - 1, size, levels), 1.0) << size;
    }
    // The old fixed 7 levels: at 512² UE4's chain stopped at r = 2^(−2/1.2) ≈ 0.315 (with the mip
    // count; 0.561 with CubemapMaxMip) and the nightly judged 512 worse than 128. Now refused.
    EXPECT_NEAR(chain_level_roughness("ue4", 6, 512, 7), std::exp2(-1 / 1.2), 1e-12);
    try {
        chain_levels("ue4", EnvLayout::cube, 512, 7);
        ADD_FAILURE() << "mips=7 at 512 accepted";
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("end at roughness 0.561, not 1"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("needs 8 to 10 levels"), std::string::npos) << e.what();
    }
    EXPECT_EQ(chain_levels("ue4", EnvLayout::cube, 128, 6), 6u); // r = 1 at mip 5: enough
    EXPECT_THROW(chain_levels("ue4", EnvLayout::cube, 128, 5), UsageError);
    EXPECT_EQ(chain_levels("filament", EnvLayout::cube, 128, 3), 3u);          // its curve ends at r = 1 by construction
    EXPECT_THROW(chain_levels("origin", EnvLayout::cube, 128, 1), UsageError); // one level cannot hold both ends
    EXPECT_THROW(chain_levels("ue4", EnvLayout::cube, 128, 9), UsageError);    // more than the cube holds
    EXPECT_THROW(chain_levels("bogus", EnvLayout::cube, 128, 0), UsageError);
}
} // namespace test_env_layout
