// ASTC storage of the prefiltered chain (renderers/mobile/astc_storage.h; issue 18): block bytes,
// the RGBM wrapper, and the round trip through ARM's codec on known data — a constant (ASTC's
// void-extent block: exact in fp16), a smooth HDR field like a prefiltered level (error bounds
// measured here, 6x6 worse than 4x4), and determinism. CPU only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "kernel/errors.h"
#include "renderers/mobile/astc_storage.h"
#include "renderers/mobile/env_layout.h"
#include "renderers/mobile/ibl_precompute.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_astc_storage {

namespace {

// A smooth HDR field over a w×h image: a broad lobe of ~200 over a 0.05..2 gradient, the kind of
// content a rough prefiltered level holds (values span 4 decades).
std::vector<float> smooth_hdr(uint32_t w, uint32_t h) {
    std::vector<float> img(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            double u = (x + 0.5) / w, v = (y + 0.5) / h;
            double lobe = 200.0 * std::exp(-((u - 0.3) * (u - 0.3) + (v - 0.6) * (v - 0.6)) / 0.02);
            double base = 0.05 + 2.0 * u * v;
            float* p = &img[4 * (size_t(y) * w + x)];
            p[0] = float(base + lobe);
            p[1] = float(0.8 * base + 0.9 * lobe);
            p[2] = float(0.6 * base + 0.7 * lobe);
            p[3] = 1;
        }
    return img;
}

// Relative RMS error of the decoded radiance (RGBM decoded with its range) against the input,
// over the RGB values at or above `floor`.
double relative_rms(const std::vector<float>& in, const AstcRoundTrip& rt, const AstcFormat& f, double floor) {
    double sum = 0;
    size_t n = in.size() / 4, counted = 0;
    for (size_t i = 0; i < n; ++i) {
        float m = f.profile == AstcProfile::ldr_rgbm ? half_bits_to_float(rt.decoded_half[4 * i + 3]) * f.rgbm_range : 1.0f;
        for (int c = 0; c < 3; ++c) {
            double d = half_bits_to_float(rt.decoded_half[4 * i + c]) * m, e = in[4 * i + c];
            if (e < floor) continue;
            sum += (d - e) * (d - e) / (e * e);
            ++counted;
        }
    }
    return std::sqrt(sum / double(counted));
}

} // namespace

TEST(AstcStorage, BytesAreSixteenPerBlockWithPartialBlocksWhole) {
    EXPECT_EQ(astc_image_bytes(128, 128, 4), 32u * 32 * 16); // 8 bits a texel
    EXPECT_EQ(astc_image_bytes(128, 128, 6), 22u * 22 * 16); // 128/6 = 21.3 → 22 blocks a side
    EXPECT_EQ(astc_image_bytes(1, 1, 4), 16u);
    EXPECT_EQ(astc_image_bytes(2, 2, 6), 16u);
    EXPECT_EQ(astc_image_bytes(7, 5, 6), 2u * 1 * 16);
    EXPECT_EQ(astc_block_from_option("6x6"), 6u);
    EXPECT_THROW(astc_block_from_option("5x5"), UsageError);
}

TEST(AstcStorage, LevelBytesOfEveryStorageFormat) {
    // One 128² cube level (6 faces): RGBA32F 16 B/texel, RGBA16F 8, RGBM8 and R11G11B10 4 (the
    // packed format's size, even where lavapipe holds it in RGBA16F), ASTC 16 B per block.
    const uint64_t texels = 128 * 128 * 6;
    EXPECT_EQ(storage_level_bytes("rgba32f", "4x4", 128, 128, 6), texels * 16);
    EXPECT_EQ(storage_level_bytes("rgba16f", "4x4", 128, 128, 6), texels * 8);
    EXPECT_EQ(storage_level_bytes("rgbm8", "4x4", 128, 128, 6), texels * 4);
    EXPECT_EQ(storage_level_bytes("r11g11b10", "4x4", 128, 128, 6), texels * 4);
    EXPECT_EQ(storage_level_bytes("astc_hdr", "4x4", 128, 128, 6), texels);
    EXPECT_EQ(storage_level_bytes("astc_ldr_rgbm", "6x6", 128, 128, 6), 6u * 22 * 22 * 16);
    // The 4x4 level of a 7-level 128 chain: a 2x2 face still takes a whole block.
    EXPECT_EQ(storage_level_bytes("astc_hdr", "6x6", 2, 2, 6), 6u * 16);
}

TEST(AstcStorage, RgbmEncodeKeepsTheRangeAndTheMinimumMultiplier) {
    float out[4];
    const float bright[3] = {3.0f, 1.5f, 0.75f};
    rgbm_encode(bright, 6.0f, out);
    EXPECT_FLOAT_EQ(out[3], 0.5f); // max 3 / range 6
    EXPECT_FLOAT_EQ(out[0], 1.0f);
    EXPECT_FLOAT_EQ(out[0] * out[3] * 6.0f, 3.0f);
    EXPECT_FLOAT_EQ(out[2] * out[3] * 6.0f, 0.75f);
    const float dark[3] = {0.01f, 0.0f, -1.0f}; // negatives clamp to 0
    rgbm_encode(dark, 6.0f, out);
    EXPECT_FLOAT_EQ(out[3], kAstcRgbmMinM);
    EXPECT_NEAR(out[0] * out[3] * 6.0f, 0.01f, 1e-7);
    EXPECT_EQ(out[2], 0.0f);
    const float over[3] = {60.0f, 6.0f, 0.0f}; // above the range: clipped at range
    rgbm_encode(over, 6.0f, out);
    EXPECT_FLOAT_EQ(out[3], 1.0f);
    EXPECT_FLOAT_EQ(out[0], 1.0f);
}

TEST(AstcStorage, ConstantImagesRoundTripToTheirFp16Value) {
    // A constant block is ASTC's void-extent block: HDR stores the colour as fp16, so the decode is
    // the input rounded to fp16 (relative error ≤ 2^-11); RGBM stores UNORM16, which decodes to
    // fp16 of m and rgb, each within 2^-11 relative, and a product within ~3 of those.
    for (uint32_t block : {4u, 6u}) {
        for (AstcProfile profile : {AstcProfile::hdr, AstcProfile::ldr_rgbm}) {
            AstcFormat f{profile, block, 6.0f};
            AstcCodec codec(f);
            const float colour[3] = {0.3f, 2.5f, profile == AstcProfile::hdr ? 1000.0f : 5.0f};
            std::vector<float> img(12 * 12 * 4);
            for (size_t i = 0; i < 144; ++i)
                for (int c = 0; c < 4; ++c) img[4 * i + c] = c < 3 ? colour[c] : 1.0f;
            AstcRoundTrip rt = codec.round_trip(img.data(), 12, 12);
            EXPECT_EQ(rt.bytes, astc_image_bytes(12, 12, block));
            double worst = 0;
            for (size_t i = 0; i < 144; ++i) {
                float m = profile == AstcProfile::ldr_rgbm ? half_bits_to_float(rt.decoded_half[4 * i + 3]) * 6.0f : 1.0f;
                for (int c = 0; c < 3; ++c)
                    worst = std::max(
                        worst, double(std::fabs(half_bits_to_float(rt.decoded_half[4 * i + c]) * m - colour[c]) / colour[c]));
            }
            EXPECT_LT(worst, profile == AstcProfile::hdr ? std::ldexp(1.0, -11) : 3 * std::ldexp(1.0, -11))
                << "block " << block << (profile == AstcProfile::hdr ? " hdr" : " rgbm");
        }
    }
}

TEST(AstcStorage, SmoothHdrFieldWithinTheMeasuredErrorAnd6x6CostsAccuracy) {
    // Measured (astcenc 4.2, quality 60, one thread) on this 64x64 field, relative RMS error:
    //   HDR over every value:                     4x4 0.0086, 6x6 0.0199
    //   RGBM (range 6) over values ≥ 1 % of it:   4x4 0.0251, 6x6 0.0433
    // RGBM's darks are coarse by design (M ≥ 16/255: steps of ~0.0015 at the bottom; every value
    // counted, its relative RMS is ~0.08), so its error is judged where its
    // precision is meant to be. Bounds: 1.5x the measured.
    const uint32_t w = 64, h = 64;
    std::vector<float> img = smooth_hdr(w, h);
    struct Case {
        AstcProfile profile;
        uint32_t block;
        double bound;
    };
    double err[2][2] = {};
    for (Case c : {Case{AstcProfile::hdr, 4, 0.013}, Case{AstcProfile::hdr, 6, 0.03}, Case{AstcProfile::ldr_rgbm, 4, 0.038},
                   Case{AstcProfile::ldr_rgbm, 6, 0.065}}) {
        AstcFormat f{c.profile, c.block, 6.0f};
        // RGBM clips above its range: scale the field into it for the LDR profile.
        std::vector<float> in = img;
        if (c.profile == AstcProfile::ldr_rgbm)
            for (size_t i = 0; i < in.size(); ++i) in[i] *= (i % 4 == 3) ? 1.0f : 5.9f / 202.05f;
        AstcCodec codec(f);
        AstcRoundTrip rt = codec.round_trip(in.data(), w, h);
        double e = relative_rms(in, rt, f, c.profile == AstcProfile::hdr ? 0.0 : 0.06);
        err[c.profile == AstcProfile::hdr ? 0 : 1][c.block == 4 ? 0 : 1] = e;
        std::printf("[ astc ] %s %ux%u relative RMS %.4g, encode %.3g ms\n", c.profile == AstcProfile::hdr ? "hdr" : "rgbm",
                    c.block, c.block, e, rt.encode_ms);
        EXPECT_LT(e, c.bound) << (c.profile == AstcProfile::hdr ? "hdr " : "rgbm ") << c.block;
        EXPECT_GT(e, 0.0); // a lossy format: nothing passes by being skipped
        EXPECT_GE(rt.encode_ms, 0.0);
    }
    EXPECT_GT(err[0][1], err[0][0]); // 6x6 (3.56 bpp) loses more than 4x4 (8 bpp)
    EXPECT_GT(err[1][1], err[1][0]);
}

TEST(AstcStorage, EncodingIsDeterministic) {
    std::vector<float> img = smooth_hdr(40, 24);
    AstcFormat f{AstcProfile::hdr, 6, 6.0f};
    AstcCodec a(f), b(f);
    EXPECT_EQ(a.round_trip(img.data(), 40, 24).decoded_half, b.round_trip(img.data(), 40, 24).decoded_half);
    EXPECT_EQ(a.round_trip(img.data(), 40, 24).decoded_half, a.round_trip(img.data(), 40, 24).decoded_half);
}

TEST(AstcStorage, HalfBitsDecode) {
    EXPECT_EQ(half_bits_to_float(0x3c00), 1.0f);
    EXPECT_EQ(half_bits_to_float(0xc000), -2.0f);
    EXPECT_EQ(half_bits_to_float(0x7bff), 65504.0f);
    EXPECT_EQ(half_bits_to_float(0x0001), std::ldexp(1.0f, -24)); // smallest subnormal
}
} // namespace test_astc_storage
