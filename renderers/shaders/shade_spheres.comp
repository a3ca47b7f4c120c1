#version 460
// Pass 5, shading=compute: per-frame shading of the mobile split-sum pipeline. Each pixel traces
// ssaa×ssaa rays against the analytic spheres (exact normals) and shades every hit with the
// split sum (split_sum.glsl, shared with the fragment path shade_spheres.frag). Specular AA takes
// its derivatives from neighbouring pixels' rays (specular_aa.glsl). Variants are defines from
// the option table (renderers/option_table.cpp).
#include "split_sum.glsl"
#include "specular_aa.glsl"
#if SHADING != SHADING_COMPUTE
#error "shade_spheres.comp is the shading=compute pass (renderers/option_table.cpp)"
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 5, std430) writeonly buffer Out { vec4 pixels[]; } out_image;

// Shades one camera ray; returns rgb and 1 in alpha for a hit, 0 for a miss.
vec4 shade_ray(vec2 p) {
    int id;
    vec3 n, v;
    if (!surface_at(p, vec2(pc.width, pc.height), id, n, v)) return vec4(0.0);
    SphereGpu s = scene.spheres[id];
    float roughness = specular_aa_roughness(s.roughness_bump.x, n, v, p, vec2(pc.width, pc.height),
                                            pc.specular_aa_variance, pc.specular_aa_threshold);
#ifdef IBL_SHADE_CONTRACT
    // The hit point, traced again: the built-in shading needs none, so surface_at keeps its cost.
    vec3 o, d;
    float t;
    camera_ray(p, vec2(pc.width, pc.height), o, d);
    intersect_scene(o, d, t);
    return vec4(shade_surface_contract(s, o + d * t, n, v, roughness), 1.0);
#else
    return vec4(shade_surface(s, n, v, roughness), 1.0);
#endif
}

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= pc.width || px.y >= pc.height) return;
    vec4 sum = vec4(0.0);
    uint n = max(pc.ssaa, 1u);
    for (uint j = 0u; j < n; ++j)
        for (uint i = 0u; i < n; ++i) sum += shade_ray(vec2(px) + (vec2(i, j) + 0.5) / float(n));
    out_image.pixels[px.y * pc.width + px.x] = sum / float(n * n); // alpha = coverage
}
