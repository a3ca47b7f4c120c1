// Roughness ↔ mip level of the prefiltered cube (option mip_mapping). The prefilter pass writes
// mip m with roughness lod_to_roughness(m); shading reads at roughness_to_lod(r): the same mapping,
// inverted (define MIP_MAPPING).
//   cubemap_max_mip = log2(base size): the last mip index of the whole chain down to 1×1, what UE4
//                     passes as CubemapMaxMip (SceneRendering.cpp: ReflectionCubemapMaxMip =
//                     FloorLog2(capture size); ReflectionEnvironment.cpp: SkyLightParameters.x =
//                     SkyMipCount − 1; its prefilter, ReflectionEnvironmentShaders.usf FilterPS,
//                     ComputeReflectionCaptureRoughnessFromMip(MipIndex, NumMips − 1)). Not the
//                     mip count: that reads one level too coarse (issue 27).
//   max_lod         = stored mip count − 1
// renderers/mobile/mip_chain.cpp is the same mapping on the host (validation, provenance, tests).
#ifndef IBLCHECK_MIP_MAPPING_GLSL
#define IBLCHECK_MIP_MAPPING_GLSL

#ifndef MIP_MAPPING
#error "MIP_MAPPING is set from the option table (renderers/option_table.cpp)"
#endif

// UE4 ReflectionEnvironmentShared.ush: REFLECTION_CAPTURE_ROUGHEST_MIP 1,
// REFLECTION_CAPTURE_ROUGHNESS_MIP_SCALE 1.2; LevelFrom1x1 = 1 − 1.2·log2(r),
// mip = CubemapMaxMip − 1 − LevelFrom1x1.
const float REFLECTION_CAPTURE_ROUGHEST_MIP = 1.0;
const float REFLECTION_CAPTURE_ROUGHNESS_MIP_SCALE = 1.2;
// The `origin` curve (first seed: "a curve that passes through the origin" so mip 0 is a mirror):
// lod = max_lod · log2(1 + k·r) / log2(1 + k), log-shaped like UE4's but 0 at r = 0.
// k = 32 puts r = 0.5 at 81 % of the chain, close to UE4's 80 % for a 7-level 128² chain.
const float ORIGIN_CURVE_K = 32.0;

float roughness_to_lod(float r, float cubemap_max_mip, float max_lod) {
#if MIP_MAPPING == MIP_MAPPING_UE4
    float level_from_1x1 = REFLECTION_CAPTURE_ROUGHEST_MIP - REFLECTION_CAPTURE_ROUGHNESS_MIP_SCALE * log2(max(r, 1e-6));
    return clamp(cubemap_max_mip - 1.0 - level_from_1x1, 0.0, max_lod);
#elif MIP_MAPPING == MIP_MAPPING_FILAMENT
    // Filament (ibl/CubemapIBL, shading: perceptualRoughnessToLod): lod = max_lod · r(2 − r).
    return clamp(max_lod * r * (2.0 - r), 0.0, max_lod);
#elif MIP_MAPPING == MIP_MAPPING_ORIGIN
    return clamp(max_lod * log2(1.0 + ORIGIN_CURVE_K * r) / log2(1.0 + ORIGIN_CURVE_K), 0.0, max_lod);
#endif
}

float lod_to_roughness(float lod, float cubemap_max_mip, float max_lod) {
#if MIP_MAPPING == MIP_MAPPING_UE4
        // ComputeReflectionCaptureRoughnessFromMip: LevelFrom1x1 = CubemapMaxMip − 1 − mip.
    return clamp(exp2((REFLECTION_CAPTURE_ROUGHEST_MIP - (cubemap_max_mip - 1.0 - lod)) / REFLECTION_CAPTURE_ROUGHNESS_MIP_SCALE), 0.0, 1.0);
#elif MIP_MAPPING == MIP_MAPPING_FILAMENT
    return clamp(1.0 - sqrt(max(0.0, 1.0 - lod / max_lod)), 0.0, 1.0);
#elif MIP_MAPPING == MIP_MAPPING_ORIGIN
    return clamp((exp2(lod / max_lod * log2(1.0 + ORIGIN_CURVE_K)) - 1.0) / ORIGIN_CURVE_K, 0.0, 1.0);
#endif
}

#endif
