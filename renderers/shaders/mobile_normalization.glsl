// UE4's mobile reflection normalisation (option normalization; second seed, and UE4's
// ReflectionEnvironmentShared.ush ComputeMixingWeight).
//   MixingAlpha  = smoothstep(0, 1, saturate((r − begin) / (end − begin)))
//   MixingWeight = min(indirect_irradiance / max(average_brightness, 1e-4), largest_weight)
//   scale        = lerp(1, MixingWeight, MixingAlpha)
// average_brightness is the rgb mean (not luminance: UE4's choice, see the seed) of the 1×1 mip,
// i.e. the mean radiance of the environment. indirect_irradiance is what a lightmap or the
// indirect-lighting cache would give: by default UE4's Luminance() of the SH9 diffuse lighting E(n)/π,
// or a constant (option indirect_irradiance). Material AO (option ao) multiplies it (seed 001: so
// an AO map darkens a metal's reflections once the normalisation mixes in).
//
// normalization=directional: seed 001's criticism of the scalar ratio — indirect_irradiance comes
// from one direction (a lightmap without directionality even from the upper hemisphere only), while
// average_brightness is the mean over all directions, so the ratio is wrong wherever the
// environment is not uniform. This variant divides by the prefiltered chain's own brightness at
// the normal instead: its r = 1 level, read along n. With n = v, GGX at α = 1 has D = 1/π, so the
// prefilter's reflected samples are uniform over the sphere and weighted by n·l: that level holds
// the cosine-weighted mean radiance E(n)/π, the same quantity as SH9's E(n)/π. When the lightmap
// agrees with the capture the scale is then ≈ 1 in every direction (what "normalised" should
// mean); where it does not, it corrects by the ratio at n.
#ifndef IBLCHECK_MOBILE_NORMALIZATION_GLSL
#define IBLCHECK_MOBILE_NORMALIZATION_GLSL
#include "precision.glsl"
#ifndef NORMALIZATION
#error "NORMALIZATION is set from the option table (renderers/option_table.cpp)"
#endif

hfloat reflection_mixing_scale(hfloat roughness, hfloat indirect_irradiance, hfloat average_brightness,
                               hfloat begin_roughness, hfloat end_roughness, hfloat largest_weight) {
#if NORMALIZATION == NORMALIZATION_UE4 || NORMALIZATION == NORMALIZATION_DIRECTIONAL
    hfloat alpha = smoothstep(hfloat(0.0), hfloat(1.0),
                              clamp((roughness - begin_roughness) / (end_roughness - begin_roughness), hfloat(0.0), hfloat(1.0)));
    hfloat weight = min(indirect_irradiance / max(average_brightness, hfloat(1e-4)), largest_weight);
    return mix(hfloat(1.0), weight, alpha);
#else
    return hfloat(1.0);
#endif
}
#endif
