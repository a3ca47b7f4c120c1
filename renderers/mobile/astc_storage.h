// ASTC storage of the prefiltered chain (options storage=astc_hdr|astc_ldr_rgbm, astc_block).
// lavapipe cannot sample ASTC, so the pipeline does what a phone's texture unit would do, on the
// CPU: every level of every face is encoded with ARM's reference codec (Debian libastcenc-dev,
// astcenc 4.2) and decoded again exactly as the format specifies, and the decoded texels are
// uploaded as RGBA16F for the sampler to filter (filtering then sees exactly the decoded texels,
// as on a device). Decoding is to fp16: the ASTC specification's default decode mode
// (decode_float16; VK_EXT_astc_decode_mode's default, R16G16B16A16_SFLOAT), for LDR (UNORM16 →
// fp16) and HDR (the block's fp16 values) alike.
//
// Determinism (goldens must be portable): one encoder thread, a fixed quality preset
// (kAstcQuality), astcenc's own invariance (its builds give the same blocks on every SIMD ISA),
// and the same first compression in every process (astc_storage.cpp: astcenc 4.2 remembers it).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "renderers/vulkan/half_float.h" // half_bits_to_float: the decoded blocks are fp16

struct astcenc_context; // astcenc.h (kept out of this header)

namespace iblcheck {

// ASTCENC_PRE_MEDIUM (60): the astcenc command line's default quality, what a content pipeline
// typically ships; fixed so encodes (and goldens) do not depend on a setting.
constexpr float kAstcQuality = 60.0f;
// Lowest RGBM multiplier (astcenc.h, ASTCENC_FLG_MAP_RGBM: "keep the minimum value of M above a
// lower threshold (try 16 or 32)", out of 255) — very small M values can quantise to 0. (The flag
// itself is not used: see AstcCodec's constructor.)
constexpr float kAstcRgbmMinM = 16.0f / 255.0f;

enum class AstcProfile {
    hdr,      // ASTC HDR (RGB HDR endpoints, LDR alpha): stores the linear radiance directly
    ldr_rgbm, // ASTC LDR (linear) of RGBM texels (range `rgbm_range`); the shader multiplies back
};

struct AstcFormat {
    AstcProfile profile = AstcProfile::hdr;
    uint32_t block = 4;      // square block footprint: 4 (4x4, 8 bpp) or 6 (6x6, 3.56 bpp)
    float rgbm_range = 6.0f; // ldr_rgbm only
};

// "4x4" → 4, "6x6" → 6; UsageError naming option 'astc_block' otherwise.
uint32_t astc_block_from_option(const std::string& value);

// Bytes of one w×h ASTC image: 16 bytes per block, partial blocks at the edges count whole.
uint64_t astc_image_bytes(uint32_t width, uint32_t height, uint32_t block);

// Linear RGB → the RGBM texel astcenc's RGBM mode expects: M = max(rgb)/range clamped to
// [kAstcRgbmMinM, 1], rgb/(M·range) clamped to [0, 1]. decode: rgb·M·range.
void rgbm_encode(const float rgb[3], float range, float out_rgbm[4]);

// One image through the codec: `rgba` holds width×height RGBA floats (linear radiance; alpha is
// ignored). Returns the decoded texels as fp16 bit patterns (RGBA; for ldr_rgbm the RGBM values,
// for hdr the radiance with alpha 1) and the compressed size.
struct AstcRoundTrip {
    std::vector<uint16_t> decoded_half; // width × height × 4
    uint64_t bytes = 0;
    double encode_ms = 0; // wall time of astcenc_compress_image (one thread)
    double decode_ms = 0;
};

class AstcCodec {
  public:
    explicit AstcCodec(const AstcFormat& format); // allocates astcenc's context (one thread)
    ~AstcCodec();
    AstcCodec(const AstcCodec&) = delete;
    AstcCodec& operator=(const AstcCodec&) = delete;

    AstcRoundTrip round_trip(const float* rgba, uint32_t width, uint32_t height);
    const AstcFormat& format() const { return format_; }

  private:
    AstcFormat format_;
    ::astcenc_context* ctx_ = nullptr;
};

} // namespace iblcheck
