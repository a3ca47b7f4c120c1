// Where the prefiltered cube is read (option dominant_dir). DOMINANT_DIR: 0 off (R), 1 lagarde,
// 2 filament. The split sum assumes n = v; at grazing angles and high roughness the real lobe
// leans toward n, and these move the lookup accordingly.
#ifndef IBLCHECK_DOMINANT_DIR_GLSL
#define IBLCHECK_DOMINANT_DIR_GLSL
#include "precision.glsl"
#ifndef DOMINANT_DIR
#define DOMINANT_DIR 0
#endif

hvec3 specular_dominant_dir(hvec3 n, hvec3 r, hfloat roughness) {
#if DOMINANT_DIR == 1
    // Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", listing 22 (first seed): not
    // normalised, as the lookup is in a cubemap.
    hfloat smoothness = clamp(hfloat(1.0) - roughness, hfloat(0.0), hfloat(1.0));
    hfloat lerp_factor = smoothness * (sqrt(smoothness) + roughness);
    return mix(n, r, lerp_factor);
#elif DOMINANT_DIR == 2
    // Filament (Filament.md, "Specular dominant direction"): mix(r, n, α²) with α = roughness².
    hfloat a = roughness * roughness;
    return mix(r, n, a * a);
#else
    return r;
#endif
}
#endif
