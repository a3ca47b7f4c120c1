#version 460
// Pass 1: equirectangular environment → cubemap base level (rgba32f), supersampled n×n per texel
// so a cube texel larger than an equirect pixel averages what it covers.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0) uniform sampler2D equirect;
layout(binding = 1, rgba32f) uniform writeonly image2DArray cube_out;
layout(push_constant) uniform Push {
    uint size;
    uint supersample;
    float env_rotation_deg;
} pc;

void main() {
    uvec3 t = gl_GlobalInvocationID;
    if (t.x >= pc.size || t.y >= pc.size) return;
    vec3 sum = vec3(0.0);
    uint n = max(pc.supersample, 1u);
    for (uint j = 0u; j < n; ++j)
        for (uint i = 0u; i < n; ++i) {
            vec2 st = (vec2(t.xy) + (vec2(i, j) + 0.5) / float(n)) / float(pc.size) * 2.0 - 1.0;
            vec3 d = rotate_y(cube_direction(t.z, st), -pc.env_rotation_deg);
            sum += textureLod(equirect, direction_to_equirect_uv(d), 0.0).rgb;
        }
    imageStore(cube_out, ivec3(t), vec4(sum / float(n * n), 1.0));
}
