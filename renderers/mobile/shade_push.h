// The shading pass's push constants, for both paths (option shading): split_sum.glsl's Push block
// (std430: twelve 4-byte members, no padding).
#pragma once
#include <cstdint>

namespace iblcheck {

struct ShadePush {
    uint32_t width, height;  // compute: the image; fragment: the framebuffer (image × ssaa)
    uint32_t ssaa;
    float full_mips, max_lod, mix_begin, mix_end, mix_largest, indirect, aa_variance, aa_threshold, rot;
};
static_assert(sizeof(ShadePush) == 48, "split_sum.glsl's Push block is 48 bytes");

} // namespace iblcheck
