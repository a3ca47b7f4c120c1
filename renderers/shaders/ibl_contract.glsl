// The shader contract (docs/SHADER_CONTRACT.md): what the harness gives a team's IBL shading and
// the one function it calls. Compiled only with a team's file (define IBL_SHADE_CONTRACT; `--shader`
// or a suite's "shader"); the built-in shading does not pass through it, so its SPIR-V, pixels
// and cost are those of split_sum.glsl alone. Needs split_sum.glsl (bindings 0..4, push constants).
#ifndef IBLCHECK_IBL_CONTRACT_GLSL
#define IBLCHECK_IBL_CONTRACT_GLSL

// One shading point. World space, right-handed, +Y up (renderers/scenes/scene.h).
struct IblSurface {
    vec3 position;              // the hit point on the sphere
    vec3 normal;                // unit shading normal (with the scene's normal detail)
    vec3 view;                  // unit, from the surface towards the eye
    vec3 base_color;            // linear, 0..1
    float metallic;             // 0..1
    float perceptual_roughness; // r, α = r²; after specular AA (the material's own with specular_aa=off)
    float ao;                   // material ambient occlusion, 0..1 (1 unless the option ao sets it)
};

// The lighting's numbers; the textures are read through the ibl_* functions below.
struct IblInputs {
    float prefiltered_levels;  // mip levels of the prefiltered radiance (mips, default the full chain)
    float cubemap_max_mip;     // log2(base face size): UE4's CubemapMaxMip
    float dfg_lut_size;        // texels per side of the DFG LUT (lut_size, default 64)
    vec3 sh9[9];               // Σ sh9[i]·Y_i(n) = E(n)/π; order 00, 1-1, 10, 11, 2-2, 2-1, 20, 21, 22 (sh9.glsl)
    vec3 mean_radiance;        // the environment's mean radiance (rgb)
};

// Prefiltered radiance along `dir` (need not be unit) at mip `lod` (fractional: trilinear), linear
// and decoded whatever the storage (rgbm8, r11g11b10, ASTC, ...) and layout (cube, octahedral,
// equirect). Level m holds GGX-prefiltered radiance at roughness ibl_lod_to_roughness(m).
vec3 ibl_prefiltered(vec3 dir, float lod) { return decode_storage(SAMPLE_ENV(prefiltered, dir, lod)); }

// The curve the prefilter wrote the levels with (option mip_mapping: ue4 | filament | origin).
float ibl_roughness_to_lod(float perceptual_roughness) {
    return roughness_to_lod(perceptual_roughness, pc.cubemap_max_mip, pc.max_lod);
}
float ibl_lod_to_roughness(float lod) { return lod_to_roughness(lod, pc.cubemap_max_mip, pc.max_lod); }

// E(n)/π, the cosine-weighted mean radiance around n: SH9 or the irradiance cube (option diffuse).
vec3 ibl_irradiance(vec3 n) { return diffuse_radiance(n); }

// The DFG LUT at (n·v, perceptual roughness): (A, B) with ∫ f_spec cos = F0·A + B (single-scatter
// GGX, height-correlated Smith, Schlick; dfg_lut.comp). Texel (i, j) holds n·v = i/(size − 1),
// r = j/(size − 1); this does the uv (dfg_lut_uv).
vec2 ibl_dfg(float n_dot_v, float perceptual_roughness) {
    vec2 uv = dfg_lut_uv(clamp(n_dot_v, 0.0, 1.0), clamp(perceptual_roughness, 0.0, 1.0), float(textureSize(dfg_lut, 0).x));
    return textureLod(dfg_lut, uv, 0.0).rg;
}

IblInputs ibl_inputs() {
    IblInputs inputs;
    inputs.prefiltered_levels = pc.max_lod + 1.0;
    inputs.cubemap_max_mip = pc.cubemap_max_mip;
    inputs.dfg_lut_size = float(textureSize(dfg_lut, 0).x);
    for (int i = 0; i < 9; ++i) inputs.sh9[i] = sh.coeffs[i].rgb;
    inputs.mean_radiance = sh.coeffs[9].rgb;
    return inputs;
}

#include "ibl_shade_user.glsl"  // the team's file (CompileOptions::ibl_shade)

// What both shading passes call under IBL_SHADE_CONTRACT instead of shade_surface.
vec3 shade_surface_contract(SphereGpu s, vec3 position, vec3 n, vec3 v, float roughness) {
    IblSurface surf;
    surf.position = position;
    surf.normal = n;
    surf.view = v;
    surf.base_color = s.base_color_metallic.rgb;
    surf.metallic = s.base_color_metallic.a;
    surf.perceptual_roughness = roughness;
#ifdef MATERIAL_AO
    surf.ao = s.ao_pad.x;
#else
    surf.ao = 1.0;
#endif
    return ibl_shade(surf, ibl_inputs());
}

#endif
