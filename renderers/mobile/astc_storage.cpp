#include "astc_storage.h"

#include <astcenc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>

#include "kernel/errors.h"

namespace iblcheck {

namespace {
void check(astcenc_error e, const char* what) {
    if (e != ASTCENC_SUCCESS)
        throw EnvironmentError(std::string("astcenc (libastcenc-dev) ") + what + ": " + astcenc_get_error_string(e));
}
// Debian 12's astcenc 4.2 keeps state from the first LDR compression of a process: the blocks of
// a later LDR encode depend on the block size that process compressed first (measured with the
// studio chain: its 4x4 blocks differ after a 6x6 encode than in a process that started with 4x4,
// and the 6x6 ones the other way round; the content of that first image does not matter; HDR is
// unaffected). The runner's workers take tests in a different order on each run, so goldens
// would depend on it. Every process therefore starts with the same first compression: a fixed
// 4x4 LDR one, before any other use of the codec.
void canonical_first_compression() {
    static std::once_flag once;
    std::call_once(once, [] {
        astcenc_config config{};
        astcenc_context* ctx = nullptr;
        check(astcenc_config_init(ASTCENC_PRF_LDR, 4, 4, 1, kAstcQuality, 0, &config), "config_init");
        check(astcenc_context_alloc(&config, 1, &ctx), "context_alloc");
        // A non-constant 8x8 image (a constant one is a void-extent block, which does not count).
        std::vector<float> texels(8 * 8 * 4);
        for (size_t i = 0; i < texels.size(); ++i) texels[i] = i % 4 == 3 ? 1.0f : float((i * 7) % 11) / 10.0f;
        void* slice = texels.data();
        astcenc_image image{8, 8, 1, ASTCENC_TYPE_F32, &slice};
        const astcenc_swizzle swz{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};
        uint8_t blocks[4 * 16];
        astcenc_error e = astcenc_compress_image(ctx, &image, &swz, blocks, sizeof blocks, 0);
        astcenc_context_free(ctx);
        check(e, "compress_image");
    });
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
} // namespace

uint32_t astc_block_from_option(const std::string& value) {
    if (value == "4x4") return 4;
    if (value == "6x6") return 6;
    throw UsageError("option 'astc_block': unknown value '" + value + "'; valid: 4x4, 6x6");
}

uint64_t astc_image_bytes(uint32_t width, uint32_t height, uint32_t block) {
    uint64_t bx = (uint64_t(width) + block - 1) / block, by = (uint64_t(height) + block - 1) / block;
    return bx * by * 16;
}

void rgbm_encode(const float rgb[3], float range, float out[4]) {
    float r = std::max(rgb[0], 0.0f), g = std::max(rgb[1], 0.0f), b = std::max(rgb[2], 0.0f);
    float m = std::clamp(std::max({r, g, b}) / range, kAstcRgbmMinM, 1.0f);
    float s = 1.0f / (m * range);
    out[0] = std::min(r * s, 1.0f);
    out[1] = std::min(g * s, 1.0f);
    out[2] = std::min(b * s, 1.0f);
    out[3] = m;
}

AstcCodec::AstcCodec(const AstcFormat& format) : format_(format) {
    if (format.block != 4 && format.block != 6)
        throw UsageError("option 'astc_block': " + std::to_string(format.block) + "x" + std::to_string(format.block) +
                         " is not supported; valid: 4x4, 6x6");
    canonical_first_compression();
    astcenc_config config{};
    bool hdr = format.profile == AstcProfile::hdr;
    // No ASTCENC_FLG_MAP_RGBM: Debian 12's astcenc 4.2 aborts in its RGBM heuristics on some 6x6
    // blocks of a prefiltered chain (assertion in block_size_descriptor::get_block_mode, reached
    // from astcenc_compress_image; the studio environment's 32x32 level at quality 60 does it).
    // The RGBM texels are compressed as plain linear LDR instead. What the flag exists to prevent
    // (M quantised to 0: black texels) is prevented by the M floor its documentation asks for
    // (kAstcRgbmMinM, applied in rgbm_encode), and M's error is weighted 2·range as it recommends,
    // since an error in M scales all three channels by up to `range`.
    check(astcenc_config_init(hdr ? ASTCENC_PRF_HDR_RGB_LDR_A : ASTCENC_PRF_LDR, format.block, format.block, 1, kAstcQuality, 0,
                              &config),
          "config_init");
    if (!hdr) config.cw_a_weight = 2.0f * format.rgbm_range;
    check(astcenc_context_alloc(&config, 1, &ctx_), "context_alloc");
}

AstcCodec::~AstcCodec() {
    if (ctx_) astcenc_context_free(ctx_);
}

AstcRoundTrip AstcCodec::round_trip(const float* rgba, uint32_t width, uint32_t height) {
    const size_t texels = size_t(width) * height;
    std::vector<float> input(texels * 4);
    const bool hdr = format_.profile == AstcProfile::hdr;
    for (size_t i = 0; i < texels; ++i) {
        if (hdr) {
            for (int c = 0; c < 3; ++c) input[4 * i + c] = std::max(rgba[4 * i + c], 0.0f);
            input[4 * i + 3] = 1.0f;
        } else {
            rgbm_encode(rgba + 4 * i, format_.rgbm_range, &input[4 * i]);
        }
    }
    void* in_slice = input.data();
    astcenc_image in{width, height, 1, ASTCENC_TYPE_F32, &in_slice};
    // HDR: RGB, alpha forced to 1 (its endpoints then cost nothing); RGBM: all four.
    const astcenc_swizzle swz_in = hdr ? astcenc_swizzle{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_1}
                                       : astcenc_swizzle{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};
    const astcenc_swizzle swz_out{ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};

    AstcRoundTrip out;
    out.bytes = astc_image_bytes(width, height, format_.block);
    std::vector<uint8_t> blocks(out.bytes);
    auto t0 = std::chrono::steady_clock::now();
    check(astcenc_compress_image(ctx_, &in, &swz_in, blocks.data(), blocks.size(), 0), "compress_image");
    out.encode_ms = ms_since(t0);
    check(astcenc_compress_reset(ctx_), "compress_reset");

    out.decoded_half.resize(texels * 4);
    void* out_slice = out.decoded_half.data();
    astcenc_image dec{width, height, 1, ASTCENC_TYPE_F16, &out_slice};
    t0 = std::chrono::steady_clock::now();
    check(astcenc_decompress_image(ctx_, blocks.data(), blocks.size(), &dec, &swz_out, 0), "decompress_image");
    out.decode_ms = ms_since(t0);
    check(astcenc_decompress_reset(ctx_), "decompress_reset");
    return out;
}

} // namespace iblcheck
