// Where the prefiltered cube is read (option dominant_dir: off reads
// along R). The split sum assumes n = v; at grazing angles and high roughness the real lobe
// leans toward n, and these move the lookup accordingly.
#ifndef IBLCHECK_DOMINANT_DIR_GLSL
#define IBLCHECK_DOMINANT_DIR_GLSL
#include "precision.glsl"
#if !defined(DOMINANT_DIR) || !defined(LAGARDE_ROUGHNESS)
#error "DOMINANT_DIR and LAGARDE_ROUGHNESS are set from the option table (renderers/option_table.cpp)"
#endif

hvec3 specular_dominant_dir(hvec3 n, hvec3 r, hfloat roughness) {
#if DOMINANT_DIR == DOMINANT_DIR_LAGARDE
    // Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", listing 22 (first seed): not
    // normalised, as the lookup is in a cubemap. Its `roughness` is α = r²: the notes' listings keep
    // `linearRoughness` for the perceptual r, and evaluateIBLSpecular (listing 24) passes
    // `roughness`, not `linearRoughness`, to getSpecularDominantDir (Blender's EEVEE passes
    // roughnessSquared too). Some ports pass the perceptual r: option lagarde_roughness=perceptual.
#if LAGARDE_ROUGHNESS == LAGARDE_ROUGHNESS_ALPHA
    hfloat a = roughness * roughness;
#elif LAGARDE_ROUGHNESS == LAGARDE_ROUGHNESS_PERCEPTUAL
    hfloat a = roughness;
#endif
    hfloat smoothness = clamp(hfloat(1.0) - a, hfloat(0.0), hfloat(1.0));
    hfloat lerp_factor = smoothness * (sqrt(smoothness) + a);
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
