// The split-sum shading of one surface point, shared by both shading paths (option shading):
// shade_spheres.comp (compute: each pixel ray-traces the spheres) and shade_spheres.frag
// (fragment: each sphere is a screen-space impostor). Both bind the same resources at the same
// bindings and push the same constants, so one host-side layout serves both.
//   color = (1 − m)·c·E(n)/π  +  prefiltered(dir, lod(r)) · (F0·A + B) · normalisation
// (Karis 2013, "Real Shading in Unreal Engine 4", split-sum approximation, eq. 3). Variants are
// defines from the option table (renderers/option_table.cpp). Needs scene.glsl (SphereGpu).
#ifndef IBLCHECK_SPLIT_SUM_GLSL
#define IBLCHECK_SPLIT_SUM_GLSL
#include "common.glsl"
#include "scene.glsl"
#include "mip_mapping.glsl"
#include "storage.glsl"
#include "env_layout.glsl"
#include "precision.glsl"
#include "env_brdf.glsl"
#include "dominant_dir.glsl"
#include "mobile_normalization.glsl"
#include "sh9.glsl"

#ifndef DIFFUSE
#error "DIFFUSE is set from the option table (renderers/option_table.cpp)"
#endif

layout(binding = 1) uniform ENV_SAMPLER prefiltered;  // a cube, or a 2D layout (env_layout.glsl)
layout(binding = 2, std140) uniform SH { vec4 coeffs[10]; } sh;  // uniform, as the scene (scene.glsl says why)
layout(binding = 3) uniform sampler2D dfg_lut;
layout(binding = 4) uniform samplerCube irradiance_cube;
layout(push_constant) uniform Push {
    uint width;                   // the frame's size in pixels (fragment: the framebuffer's)
    uint height;
    uint ssaa;                    // compute: n x n rays per pixel; fragment: unused (the host supersamples)
    float cubemap_max_mip;     // log2(base size): UE4's CubemapMaxMip (mip_mapping.glsl)
    float max_lod;
    float mix_begin_roughness;
    float mix_end_roughness;
    float mix_largest_weight;
    float indirect_irradiance;    // < 0: from SH9 at n
    float specular_aa_variance;   // Tokuyoshi & Kaplanyan σ² scale
    float specular_aa_threshold;  // κ clamp
    float env_rotation_deg;       // unused here (baked into the cube); kept for layout parity
} pc;

// UE4's Luminance() (Common.ush): dot(c, (0.3, 0.59, 0.11)).
const hvec3 UE4_LUMINANCE = hvec3(0.3, 0.59, 0.11);

vec3 diffuse_radiance(vec3 n) {
#if DIFFUSE == DIFFUSE_IRRADIANCE_CUBE
    return textureLod(irradiance_cube, n, 0.0).rgb;
#else
    return sh9_eval(sh.coeffs, n);
#endif
}

// Radiance leaving sphere `s` towards the eye at normal n, view v (unit), with the roughness
// specular AA chose (the material's own when specular_aa=off).
vec3 shade_surface(SphereGpu s, vec3 n, vec3 v, float roughness) {
    vec3 base = s.base_color_metallic.rgb;
    float metallic = s.base_color_metallic.a;

    vec3 diffuse_light = diffuse_radiance(n);
#ifdef MATERIAL_AO
    // Material AO (option ao): UE4 multiplies the indirect lighting by it, the diffuse and the
    // indirect_irradiance its normalisation reads alike (seed 001), never the reflection itself.
    diffuse_light *= s.ao_pad.x;
#endif

    hvec3 hn = hvec3(n), hv = hvec3(v);
    hfloat hr = hfloat(roughness);
    hfloat n_dot_v = max(dot(hn, hv), hfloat(1e-4));
    hvec3 refl = hfloat(2.0) * dot(hn, hv) * hn - hv;
    vec3 dir = vec3(specular_dominant_dir(hn, refl, hr));
    float lod = roughness_to_lod(roughness, pc.cubemap_max_mip, pc.max_lod);
    hvec3 spec_light = hvec3(decode_storage(SAMPLE_ENV(prefiltered, dir, lod)));

#if ENV_BRDF == ENV_BRDF_LUT
    hvec2 ab = hvec2(textureLod(dfg_lut, dfg_lut_uv(float(n_dot_v), roughness, float(textureSize(dfg_lut, 0).x)), 0.0).rg);
#else
    hvec2 ab = env_brdf_approx(hr, n_dot_v);
#endif
    hvec3 f0 = mix(hvec3(0.04), hvec3(base), hfloat(metallic));
    hvec3 specular = spec_light * (f0 * ab.x + ab.y);

    // UE4 (BasePassPixelShader.usf, GetPrecomputedIndirectLightingAndSkyLight): IndirectIrradiance =
    // Luminance(DiffuseLighting), its Luminance's weights; the rgb mean is for the capture's average
    // brightness only (below).
    hfloat indirect = pc.indirect_irradiance >= 0.0 ? hfloat(pc.indirect_irradiance)
                                                    : dot(hvec3(diffuse_light), UE4_LUMINANCE);
#ifdef MATERIAL_AO
    if (pc.indirect_irradiance >= 0.0) indirect *= hfloat(s.ao_pad.x);  // from SH9 it has the AO already
#endif
#if NORMALIZATION == NORMALIZATION_DIRECTIONAL
    // The chain's own brightness at n, from its r = 1 level: E(n)/π (mobile_normalization.glsl), in
    // the same Luminance() as indirect_irradiance, so that the ratio is 1 where the two agree.
    hfloat average_brightness = dot(hvec3(decode_storage(SAMPLE_ENV(prefiltered, n, roughness_to_lod(1.0, pc.cubemap_max_mip, pc.max_lod)))),
                                    UE4_LUMINANCE);
#else
    hfloat average_brightness = dot(hvec3(sh.coeffs[9].rgb), hvec3(1.0 / 3.0));
#endif
    specular *= reflection_mixing_scale(hr, indirect, average_brightness, hfloat(pc.mix_begin_roughness),
                                        hfloat(pc.mix_end_roughness), hfloat(pc.mix_largest_weight));

    hvec3 diffuse = hfloat(1.0 - metallic) * hvec3(base) * hvec3(diffuse_light);
    return vec3(diffuse + specular);
}

#ifdef IBL_SHADE_CONTRACT
#include "ibl_contract.glsl"  // a team's shading instead (docs/SHADER_CONTRACT.md)
#endif
#endif
