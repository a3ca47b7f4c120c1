#version 460
// Pass 5, shading=fragment: the mobile split sum as a phone runs it. Each sphere is a screen-space
// impostor (shade_spheres.vert): this shader intersects its sphere analytically, writes the hit's
// depth, sets per-sample coverage at the silhouette (MSAA 4x, standard sample locations, one
// shading per pixel) and discards fragments that cover no sample. The shading is split_sum.glsl,
// the compute path's; specular AA takes dFdx/dFdy from the hardware's 2x2 quads.
#include "split_sum.glsl"
#include "specular_aa.glsl"
#include "impostor.glsl"
#if SHADING != SHADING_FRAGMENT
#error "shade_spheres.frag and .vert are the shading=fragment pass (renderers/option_table.cpp)"
#endif

layout(location = 0) flat in CameraGpu cam;  // shade_spheres.vert
layout(location = 4) flat in SphereGpu s;
layout(location = 0) out vec4 color;  // rgb, alpha 1: the resolve averages it into coverage

// Vulkan's standard locations for 4 samples (spec, "Multisampling"; the host checks
// standardSampleLocations), in pixel units from the pixel's corner.
const vec2 SAMPLES_4X[4] = vec2[](vec2(0.375, 0.125), vec2(0.875, 0.375), vec2(0.125, 0.625), vec2(0.625, 0.875));

void main() {
    vec2 size = vec2(pc.width, pc.height);
    vec2 corner = floor(gl_FragCoord.xy);
    // The pixel centre's surface (clamped to the silhouette where the centre misses) feeds the
    // derivatives, taken here in uniform control flow, before any discard: helper and edge pixels
    // contribute as extrapolated attributes do on a mesh.
    vec3 n, v;
    float t;
    bool centre_hit = impostor_surface(cam, s, gl_FragCoord.xy, size, true, n, v, t);
    vec3 r = reflect(-v, n);
    vec3 dn_dx = dFdx(n), dn_dy = dFdy(n), dr_dx = dFdx(r), dr_dy = dFdy(r);

    // Coverage: the samples whose rays hit the sphere. Where the centre misses, shading moves to
    // the first covered sample, as centroid interpolation does.
    uint mask = 0u;
#ifdef IBL_SHADE_CONTRACT
    vec2 shading_point = gl_FragCoord.xy;  // where the shading's ray starts (the contract's position)
#endif
    for (int k = 0; k < 4; ++k) {
        vec3 nk, vk;
        float tk;
        if (impostor_surface(cam, s, corner + SAMPLES_4X[k], size, false, nk, vk, tk)) {
            if (mask == 0u && !centre_hit) {
                n = nk;
                v = vk;
                t = tk;
#ifdef IBL_SHADE_CONTRACT
                shading_point = corner + SAMPLES_4X[k];
#endif
            }
            mask |= 1u << k;
        }
    }
    if (mask == 0u) discard;

    float roughness = specular_aa_roughness_from_derivatives(s.roughness_bump.x, n, dn_dx, dn_dy, dr_dx, dr_dy,
                                                             pc.specular_aa_variance, pc.specular_aa_threshold);
#ifdef IBL_SHADE_CONTRACT
    vec3 o, d;
    camera_ray_of(cam, shading_point, size, o, d);
    color = vec4(shade_surface_contract(s, o + d * t, n, v, roughness), 1.0);
#else
    color = vec4(shade_surface(s, n, v, roughness), 1.0);
#endif
    gl_SampleMask[0] = int(mask);
    gl_FragDepth = t / (t + 1.0);  // monotonic in t, in [0, 1): the nearest hit along the ray wins
}
