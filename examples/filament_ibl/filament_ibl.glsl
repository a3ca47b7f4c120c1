// Filament's image-based lighting, written against iblcheck's shader contract
// (docs/SHADER_CONTRACT.md) from the description in Google's "Physically Based Rendering in
// Filament" (Filament.md: "Image based lights", "Energy loss in specular reflectance",
// "Specular occlusion") and its shading sources' documented conventions. Our own code: only the
// contract's IblSurface, IblInputs and ibl_* functions come from the harness.
//
//   Fd = (1 − m)·c · E(n)/π · (1 − E_spec) · ao              (SH irradiance, Lambert baked in)
//   Fr = mix(DFG.x, DFG.y, F0) · L_pre(dir, lod) · (1 + F0 (1/DFG.y − 1)) · specAO
// with the multiscatter DFG (x = B, y = A + B of the contract's single-scatter (A, B)),
// lod = (levels − 1)·r(2 − r) (Filament's perceptual-roughness-to-lod curve: run with
// mip_mapping=filament so the prefilter wrote the levels with the same curve), the reflection
// bent towards n by α² and Lagarde's specular occlusion from the material AO.

const float FIL_PI = 3.14159265358979;

// Σ c_i Y_i(n) with the real SH basis of bands 0-2 (the contract's order and normalisation; Filament
// pre-multiplies these constants into its coefficients, the contract does not).
vec3 fil_irradiance_sh(IblInputs ibl, vec3 n) {
    const float k0 = 0.5 * sqrt(1.0 / FIL_PI);
    const float k1 = sqrt(3.0 / (4.0 * FIL_PI));
    const float k2 = 0.5 * sqrt(15.0 / FIL_PI);
    const float k20 = 0.25 * sqrt(5.0 / FIL_PI);
    const float k22 = 0.25 * sqrt(15.0 / FIL_PI);
    vec3 e = ibl.sh9[0] * k0;
    e += k1 * (ibl.sh9[1] * n.y + ibl.sh9[2] * n.z + ibl.sh9[3] * n.x);
    e += k2 * (ibl.sh9[4] * (n.x * n.y) + ibl.sh9[5] * (n.y * n.z) + ibl.sh9[7] * (n.x * n.z));
    e += ibl.sh9[6] * (k20 * (3.0 * n.z * n.z - 1.0)) + ibl.sh9[8] * (k22 * (n.x * n.x - n.y * n.y));
    return max(e, vec3(0.0));
}

// Filament's lod for a perceptual roughness: the curve lod = L·r(2 − r), L the last level.
float fil_lod(IblInputs ibl, float perceptual_roughness) {
    return (ibl.prefiltered_levels - 1.0) * perceptual_roughness * (2.0 - perceptual_roughness);
}

// Lagarde & de Rousiers 2014 ("Moving Frostbite to PBR"), as Filament applies it to the
// material's AO: roughness is α.
float fil_specular_ao(float n_dot_v, float ao, float alpha) {
    return clamp(pow(n_dot_v + ao, exp2(-16.0 * alpha - 1.0)) - 1.0 + ao, 0.0, 1.0);
}

vec3 ibl_shade(IblSurface s, IblInputs ibl) {
    vec3 n = s.normal, v = s.view;
    float r = clamp(s.perceptual_roughness, 0.0, 1.0);
    float alpha = r * r;
    float n_dot_v = max(dot(n, v), 1e-4);
    vec3 f0 = mix(vec3(0.04), s.base_color, s.metallic);

    // Multiscatter DFG from the contract's single-scatter (A, B): x = B, y = A + B.
    vec2 ab = ibl_dfg(n_dot_v, r);
    vec2 dfg = vec2(ab.y, ab.x + ab.y);
    vec3 e_spec = mix(dfg.xxx, dfg.yyy, f0);
    vec3 energy_compensation = 1.0 + f0 * (1.0 / max(dfg.y, 1e-4) - 1.0);

    vec3 refl = reflect(-v, n);
    vec3 dir = mix(refl, n, alpha * alpha);  // towards the dominant direction of the lobe
    vec3 radiance = ibl_prefiltered(dir, fil_lod(ibl, r));

    vec3 fr = e_spec * radiance * energy_compensation * fil_specular_ao(n_dot_v, s.ao, alpha);
    vec3 fd = (1.0 - s.metallic) * s.base_color * fil_irradiance_sh(ibl, n) * (1.0 - e_spec) * s.ao;
    return fd + fr;
}
