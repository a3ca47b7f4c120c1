// Where the prefiltered cube is read (option dominant_dir: off reads
// along R). The split sum assumes n = v; at grazing angles and high roughness the real lobe
// leans toward n, and these move the lookup accordingly.
#ifndef IBLCHECK_DOMINANT_DIR_GLSL
#define IBLCHECK_DOMINANT_DIR_GLSL
#include "precision.glsl"
#ifndef DOMINANT_DIR
#error "DOMINANT_DIR is set from the option table (renderers/option_table.cpp)"
#endif

hvec3 specular_dominant_dir(hvec3 n, hvec3 r, hfloat roughness) {
#if DOMINANT_DIR == DOMINANT_DIR_LAGARDE
    // Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", listing 22 (first seed): not
    // normalised, as the lookup is in a cubemap.
    hfloat smoothness = clamp(hfloat(1.0) - roughness, hfloat(0.0), hfloat(1.0));
    hfloat lerp_factor = smoothness * (sqrt(smoothness) + roughness);
    return mix(n, r, lerp_factor);
#elif DOMINANT_DIR == DOMINANT_DIR_FILAMENT
    // Filament (Filament.md, "Specular dominant direction"): mix(r, n, α²) with α = roughness².
    hfloat a = roughness * roughness;
    return mix(r, n, a * a);
#elif DOMINANT_DIR == DOMINANT_DIR_OFF
    return r;
#endif
}
#endif
