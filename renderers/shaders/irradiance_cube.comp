#version 460
// Pass 3b (diffuse=irradiance_cube): an irradiance cubemap by brute-force cosine convolution of a
// low source mip, E(n)/π = (1/π) Σ L(ω) max(n·ω, 0) Δω, stored rgba32f. The SH9 alternative is
// cheaper and band-limited; this one keeps higher frequencies (the comparison the seed makes).
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rgba32f) uniform readonly image2DArray source;
layout(binding = 1, rgba32f) uniform writeonly image2DArray dst;
layout(push_constant) uniform Push { uint dst_size; uint source_size; } pc;

void main() {
    uvec3 t = gl_GlobalInvocationID;
    if (t.x >= pc.dst_size || t.y >= pc.dst_size) return;
    vec3 n = cube_texel_direction(t, pc.dst_size);
    vec3 sum = vec3(0.0);
    for (uint f = 0u; f < 6u; ++f)
        for (uint y = 0u; y < pc.source_size; ++y)
            for (uint x = 0u; x < pc.source_size; ++x) {
                uvec3 s = uvec3(x, y, f);
                float c = dot(n, cube_texel_direction(s, pc.source_size));
                if (c > 0.0) sum += imageLoad(source, ivec3(s)).rgb * (c * cube_texel_solid_angle(s.xy, pc.source_size));
            }
    imageStore(dst, ivec3(t), vec4(sum / PI, 1.0));
}
