// The push constants of every compute and graphics pass of the Vulkan methods, declared once on
// the host, each beside the GLSL block it mirrors. The blocks hold only 4-byte scalars, so std430
// puts them in order without padding; each static_assert checks the struct has the block's size,
// and pipelines are created with sizeof the struct.
#pragma once
#include <cstdint>

namespace iblcheck {

// split_sum.glsl's Push (shade_spheres.comp and shade_spheres.frag, both paths of option shading).
struct ShadePush {
    uint32_t width, height; // compute: the image; fragment: the framebuffer (image × ssaa)
    uint32_t ssaa;
    float cubemap_max_mip, max_lod, mix_begin, mix_end, mix_largest, indirect, aa_variance, aa_threshold, rot;
};
static_assert(sizeof(ShadePush) == 48, "split_sum.glsl's Push block is 48 bytes");

// shade_sampled.comp's Push.
struct SampledPush {
    uint32_t width, height, ssaa, sample_count, source_size, seed;
    float source_max_lod, min_lod, diffuse_roughness;
};
static_assert(sizeof(SampledPush) == 36, "shade_sampled.comp's Push block is 36 bytes");

// equirect_to_cube.comp's Push.
struct EquirectToCubePush {
    uint32_t size, supersample;
    float env_rotation_deg;
};
static_assert(sizeof(EquirectToCubePush) == 12, "equirect_to_cube.comp's Push block is 12 bytes");

// downsample_cube.comp's Push.
struct DownsamplePush {
    uint32_t dst_size;
};
static_assert(sizeof(DownsamplePush) == 4, "downsample_cube.comp's Push block is 4 bytes");

// prefilter_ggx.comp's Push.
struct PrefilterPush {
    uint32_t mip, dst_size, source_size, sample_count; // dst_size: cube face size, or a 2D level's width
    float cubemap_max_mip, max_lod, source_max_lod;    // cubemap_max_mip: log2(cube_size), mip_mapping.glsl
};
static_assert(sizeof(PrefilterPush) == 28, "prefilter_ggx.comp's Push block is 28 bytes");

// encode_storage.comp's Push.
struct EncodeStoragePush {
    uint32_t width, height; // the level's size (a cube face's, or a 2D layout level's)
};
static_assert(sizeof(EncodeStoragePush) == 8, "encode_storage.comp's Push block is 8 bytes");

// sh9_project.comp's Push.
struct Sh9Push {
    uint32_t size;
};
static_assert(sizeof(Sh9Push) == 4, "sh9_project.comp's Push block is 4 bytes");

// dfg_lut.comp's Push.
struct DfgLutPush {
    uint32_t size, sample_count;
};
static_assert(sizeof(DfgLutPush) == 8, "dfg_lut.comp's Push block is 8 bytes");

// irradiance_cube.comp's Push.
struct IrradiancePush {
    uint32_t dst_size, source_size;
};
static_assert(sizeof(IrradiancePush) == 8, "irradiance_cube.comp's Push block is 8 bytes");

} // namespace iblcheck
