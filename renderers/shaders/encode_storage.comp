#version 460
// Pass 2b: the prefiltered chain in the storage format asked for (storage.glsl encode_storage), one
// level per dispatch. prefilter_ggx.comp writes the chain once in rgba32f (its encode_storage for
// rgba32f: vec4(max(result, 0), 1)), and the variants that differ only in storage, the DFG table or
// the irradiance cube share it (ibl_precompute.cpp: the radiance chain; issue 33). Every encoding
// starts with max(c, 0), which is idempotent, so encoding the stored max(result, 0) gives the bits
// that encoding `result` inside the prefilter gave. A 2D layout's border texels are copied as they
// are (the prefilter computed them as the inner texels they mirror).
#include "common.glsl"
#include "env_layout.glsl"
#include "storage.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rgba32f) uniform readonly ENV_IMAGE src;
layout(binding = 1, STORAGE_FORMAT) uniform writeonly ENV_IMAGE dst;
layout(push_constant) uniform Push {
    uint width;  // this level's texels per row (a cube face's size)
    uint height;
} pc;

void main() {
    uvec3 t = gl_GlobalInvocationID;
    if (t.x >= pc.width || t.y >= pc.height) return;
#if ENV_LAYOUT == ENV_LAYOUT_CUBE
    imageStore(dst, ivec3(t), encode_storage(imageLoad(src, ivec3(t)).rgb));
#else
    imageStore(dst, ivec2(t.xy), encode_storage(imageLoad(src, ivec2(t.xy)).rgb));
#endif
}
