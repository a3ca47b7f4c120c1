#version 460
// The importance-sampled peer (third seed; Karis 2013 "Real Shading in UE4" p. 4; Colbert &
// Křivánek 2008 for the filtered lookups): per ray, N GGX samples from a Hammersley set rotated
// per pixel, each reading the source pyramid at the FIS lod, estimating
//   ∫ L f_spec cos  ≈  (1/N) Σ L(l) · F(v·h) · V · 4 (v·h)(n·l) / (n·h)        (pdf = D(n·h)/(4 v·h))
// with the model's exact D, V and F (no split sum, no n = v). Diffuse from SH9, as Substance does.
// As r → 1 the GGX lobe nears a uniform one and, as the seed proposes, the incoming radiance blends
// to the cosine-weighted irradiance E(n)/π from DIFFUSE_ROUGHNESS up to r = 1, which removes the
// remaining noise at high roughness.
// The lod is clamped below by the option min_lod and, as the seed does (mip_clamp=roughness, "I
// clamped the min mip level ... depending on roughness"), by the finest level worth reading for the
// lobe: the reflected lobe spans about 2α radians, and a level-m texel about (π/2)·2^m / base, so
// levels finer than a quarter of the lobe, 2^m < α·base/π, only add noise (and cost: the seed's
// frame times fall from mip 0 to mip 3).
#include "common.glsl"
#include "brdf.glsl"
#include "scene.glsl"
#include "sh9.glsl"
#ifndef MIP_CLAMP
#error "MIP_CLAMP is set from the option table (renderers/option_table.cpp)"
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 1) uniform samplerCube source;   // rgba32f box pyramid
layout(binding = 2, std140) uniform SH { vec4 coeffs[10]; } sh;  // uniform, as the scene (scene.glsl says why)
layout(binding = 5, std430) writeonly buffer Out { vec4 pixels[]; } out_image;
layout(push_constant) uniform Push {
    uint width;
    uint height;
    uint ssaa;
    uint sample_count;
    uint source_size;
    uint seed;
    float source_max_lod;
    float min_lod;
    float diffuse_roughness;
} pc;

vec4 shade_ray(vec2 p, uint sub) {
    int id;
    vec3 n, v;
    if (!surface_at(p, vec2(pc.width, pc.height), id, n, v)) return vec4(0.0);
    SphereGpu s = scene.spheres[id];
    vec3 base = s.base_color_metallic.rgb;
    float metallic = s.base_color_metallic.a;
    float r = s.roughness_bump.x;
    float alpha = max(r * r, 1e-4);
    vec3 f0 = mix(vec3(0.04), base, metallic);
    float n_dot_v = max(dot(n, v), 1e-4);
    vec3 irradiance = sh9_eval(sh.coeffs, n);
    float to_diffuse = r >= 1.0 ? 1.0 : smoothstep(pc.diffuse_roughness, 1.0, r);
    float omega_p = 4.0 * PI / (6.0 * float(pc.source_size * pc.source_size));
#if MIP_CLAMP == MIP_CLAMP_ROUGHNESS
    float lowest_lod = max(pc.min_lod, log2(max(alpha * float(pc.source_size) / PI, 1.0)));
#elif MIP_CLAMP == MIP_CLAMP_OFF
    float lowest_lod = pc.min_lod;
#endif

    vec3 spec = vec3(0.0);
    vec2 rot = random_rotation(uvec3(uvec2(p * 16.0), pc.seed * 977u + sub));
    for (uint i = 0u; i < pc.sample_count; ++i) {
        vec2 xi = fract(hammersley(i, pc.sample_count) + rot);
        vec3 h = importance_sample_ggx(xi, alpha, n);
        float v_dot_h = dot(v, h);
        vec3 l = 2.0 * v_dot_h * h - v;
        float n_dot_l = dot(n, l);
        if (n_dot_l <= 0.0 || v_dot_h <= 0.0) continue;
        float n_dot_h = max(dot(n, h), 1e-8);
        float pdf = d_ggx(n_dot_h, alpha) * n_dot_h / (4.0 * v_dot_h);
        float omega_s = 1.0 / (float(pc.sample_count) * pdf + 1e-8);
        float lod = clamp(0.5 * log2(omega_s / omega_p) + 1.0, min(lowest_lod, pc.source_max_lod), pc.source_max_lod);
        vec3 radiance = mix(textureLod(source, l, lod).rgb, irradiance, to_diffuse);
        float weight = v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha) * 4.0 * v_dot_h * n_dot_l / n_dot_h;
        spec += radiance * f_schlick(f0, v_dot_h) * weight;
    }
    spec /= float(pc.sample_count);
    vec3 diffuse = (1.0 - metallic) * base * irradiance;
    return vec4(diffuse + spec, 1.0);
}

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= pc.width || px.y >= pc.height) return;
    vec4 sum = vec4(0.0);
    uint n = max(pc.ssaa, 1u);
    for (uint j = 0u; j < n; ++j)
        for (uint i = 0u; i < n; ++i) sum += shade_ray(vec2(px) + (vec2(i, j) + 0.5) / float(n), j * n + i);
    out_image.pixels[px.y * pc.width + px.x] = sum / float(n * n);
}
