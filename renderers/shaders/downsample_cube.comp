#version 460
// Box-filtered mip chain of the source cube (2×2 average per face): the radiance pyramid that
// filtered importance sampling reads (Křivánek & Colbert 2008).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rgba32f) uniform readonly image2DArray src;
layout(binding = 1, rgba32f) uniform writeonly image2DArray dst;
layout(push_constant) uniform Push { uint dst_size; } pc;

void main() {
    uvec3 t = gl_GlobalInvocationID;
    if (t.x >= pc.dst_size || t.y >= pc.dst_size) return;
    ivec3 s = ivec3(t.xy * 2u, t.z);
    vec4 c = imageLoad(src, s) + imageLoad(src, s + ivec3(1, 0, 0)) + imageLoad(src, s + ivec3(0, 1, 0)) +
             imageLoad(src, s + ivec3(1, 1, 0));
    imageStore(dst, ivec3(t), c * 0.25);
}
