#version 460
// Pass 2: GGX prefiltered specular mip chain (the split sum's first factor, Karis 2013 eq. 3 with
// n = v = r), with filtered importance sampling (Křivánek & Colbert 2008, GPU Gems 3 ch. 20):
// each sample reads the source pyramid at the lod whose texel solid angle matches the sample's,
//   lod = 0.5·log2(Ωs / Ωp) + 1,  Ωs = 1 / (N · pdf),  Ωp = 4π / (6 · base²),  pdf = D(h) / 4 at n = v.
// Hammersley points are rotated per texel (random_rotation), which trades banding for noise.
// Every level m holds roughness lod_to_roughness(m), the curve the lookup inverts (mip_mapping.glsl),
// mip 0 included: a level is a copy of the source (a mirror) only where the curve assigns it
// r < 0.01, UE4's threshold (ReflectionEnvironmentShaders.usf FilterPS). So UE4's curve, which gives
// a 128² chain's mip 0 r ≈ 0.056, gets a filtered mip 0, and filament/origin (r = 0 there) a mirror.
// The destination is a cube level or, for a 2D env_layout, one level of the octahedral or lat-long
// map with its border (env_layout.glsl): a border texel is computed as the inner texel it copies
// (same direction, same random rotation), so it holds exactly that texel's value.
// The chain is written once in rgba32f (ibl_precompute.cpp: the radiance chain) and stored in the
// format asked for by encode_storage.comp (pass 2b), so storage variants share one prefilter.
#include "common.glsl"
#include "env_layout.glsl"
#include "brdf.glsl"
#include "mip_mapping.glsl"
#include "storage.glsl"

// Below this roughness a level is a copy of the source level of its own size (UE4 FilterPS: 0.01).
const float MIRROR_ROUGHNESS = 0.01;

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0) uniform samplerCube source;   // rgba32f, box-filtered pyramid
layout(binding = 1, STORAGE_FORMAT) uniform writeonly ENV_IMAGE dst;
layout(push_constant) uniform Push {
    uint mip;
    uint dst_size;        // cube: face size; 2D layout: level width
    uint source_size;
    uint sample_count;
    float cubemap_max_mip;     // log2(base size): UE4's CubemapMaxMip (mip_mapping.glsl)
    float max_lod;
    float source_max_lod;
} pc;

void main() {
    uvec3 t = gl_GlobalInvocationID;
#if ENV_LAYOUT == ENV_LAYOUT_CUBE
    if (t.x >= pc.dst_size || t.y >= pc.dst_size) return;
    vec3 n = cube_texel_direction(t, pc.dst_size);
    uvec3 seed_texel = t;
#else
    uvec2 size = layout_level_size(pc.dst_size);
    if (t.x >= size.x || t.y >= size.y) return;
    ivec2 source_texel = layout_source_texel(t.xy, size);
    vec3 n = layout_texel_direction(source_texel, size);
    uvec3 seed_texel = uvec3(source_texel, 0u);
#endif
    vec3 result;
    float r = lod_to_roughness(float(pc.mip), pc.cubemap_max_mip, pc.max_lod);
    if (r < MIRROR_ROUGHNESS) {
        result = textureLod(source, n, float(pc.mip)).rgb;
    } else {
        float alpha = max(r * r, 1e-4);
        float omega_p = 4.0 * PI / (6.0 * float(pc.source_size * pc.source_size));
        vec2 rot = random_rotation(uvec3(seed_texel.xy, seed_texel.z + 6u * pc.mip));
        vec3 sum = vec3(0.0);
        float weight = 0.0;
        for (uint i = 0u; i < pc.sample_count; ++i) {
            vec2 xi = fract(hammersley(i, pc.sample_count) + rot);
            vec3 h = importance_sample_ggx(xi, alpha, n);
            vec3 l = normalize(2.0 * dot(n, h) * h - n);
            float n_dot_l = dot(n, l);
            if (n_dot_l <= 0.0) continue;
            float n_dot_h = max(dot(n, h), 0.0);
            float pdf = d_ggx(n_dot_h, alpha) * 0.25;
            float omega_s = 1.0 / (float(pc.sample_count) * pdf + 1e-8);
            float lod = clamp(0.5 * log2(omega_s / omega_p) + 1.0, 0.0, pc.source_max_lod);
            sum += textureLod(source, l, lod).rgb * n_dot_l;
            weight += n_dot_l;
        }
        result = sum / max(weight, 1e-8);
    }
#if ENV_LAYOUT == ENV_LAYOUT_CUBE
    imageStore(dst, ivec3(t), encode_storage(result));
#else
    imageStore(dst, ivec2(t.xy), encode_storage(result));
#endif
}
