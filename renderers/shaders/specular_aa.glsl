// Specular anti-aliasing for low roughness (option specular_aa). Each widens the GGX lobe where the normal (or the reflection
// vector) varies within a pixel, so the prefiltered lookup averages what the pixel covers instead
// of point-sampling a highlight that then sparkles from frame to frame. Fresnel is untouched: only
// the roughness changes. The derivatives come from the shading path (option shading): a compute
// shader has no dFdx, so shading=compute takes forward differences of the neighbouring pixels'
// surfaces (specular_aa_roughness, what a fragment quad computes); shading=fragment passes the
// hardware quads' dFdx/dFdy (specular_aa_roughness_from_derivatives). Needs scene.glsl.
//   variance  σ²: screen-space variance scale (Tokuyoshi & Kaplanyan use 0.25)
//   threshold κ: clamp of the added α² (0.18)
#ifndef IBLCHECK_SPECULAR_AA_GLSL
#define IBLCHECK_SPECULAR_AA_GLSL
#ifndef SPECULAR_AA
#error "SPECULAR_AA is set from the option table (renderers/option_table.cpp)"
#endif
#ifndef SHADING
#error "SHADING is set from the option table (renderers/option_table.cpp)"
#endif

float roughness_from_alpha2(float alpha2) { return sqrt(sqrt(clamp(alpha2, 0.0, 1.0))); }

// The variants' added α², written once for both derivative sources.
// Tokuyoshi & Kaplanyan 2019, "Improved Geometric Specular Antialiasing" (eq. 13–14; the form
// Filament ships): α'² = α² + min(2σ²(|∂n/∂x|² + |∂n/∂y|²), κ).
float tokuyoshi_kernel(vec3 dn_dx, vec3 dn_dy, float variance) {
    return 2.0 * variance * (dot(dn_dx, dn_dx) + dot(dn_dy, dn_dy));
}
// The first seed's idea: find where the reflection vector R jumps across the pixel and widen the
// lobe to cover the jump. R = 2(n·v)n − v moves about twice as fast as n (more at grazing
// angles), hence the /4 that puts σ² on the same scale as tokuyoshi's.
float rjump_kernel(vec3 dr_dx, vec3 dr_dy, float variance) {
    return 2.0 * variance * 0.25 * (dot(dr_dx, dr_dx) + dot(dr_dy, dr_dy));
}
// Toksvig 2005, "Mipmapping Normal Maps": the mean of the normals over the pixel footprint is
// shorter than 1 where they disagree; α'² = α² + (1 − |n̄|)/|n̄| (the GGX form in Hill's "Specular
// Showdown"), scaled by σ²/0.25. Toksvig's own relation (s' = s/(1 + sσ_T²), s ≈ 2/α²) adds twice
// that, which this applies at σ² = 0.5; and σ² does not mean what it means for tokuyoshi: on a
// normal varying linearly across the pixel this adds 1/16 of tokuyoshi's α² at the same σ²
// (tests/test_specular_aa_kernel.cpp). `sum`: the sum of four unit normals spread over the pixel.
float toksvig_kernel(vec3 sum, float variance) {
    float len = length(sum * 0.25);
    return 4.0 * variance * (1.0 - len) / max(len, 1e-4);  // = σ² at the default variance 0.25
}

#if SHADING == SHADING_FRAGMENT
// The same variants from derivatives the caller took with dFdx/dFdy (shading=fragment: the
// hardware's 2x2 quads, so a quad's pixels share one difference per axis, as on a phone).
// Toksvig's four normals are the centre's extrapolated to ±¼ pixel along the derivatives, where
// the compute path traces four sub-pixel rays.
float specular_aa_roughness_from_derivatives(float roughness, vec3 n, vec3 dn_dx, vec3 dn_dy, vec3 dr_dx, vec3 dr_dy,
                                             float variance, float threshold) {
#if SPECULAR_AA == SPECULAR_AA_OFF
    return roughness;
#else
    float alpha2 = roughness * roughness * roughness * roughness;
#if SPECULAR_AA == SPECULAR_AA_TOKUYOSHI
    float kernel = tokuyoshi_kernel(dn_dx, dn_dy, variance);
#elif SPECULAR_AA == SPECULAR_AA_RJUMP
    float kernel = rjump_kernel(dr_dx, dr_dy, variance);
#elif SPECULAR_AA == SPECULAR_AA_TOKSVIG
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) sum += normalize(n + (float(i) - 0.5) * 0.5 * dn_dx + (float(j) - 0.5) * 0.5 * dn_dy);
    float kernel = toksvig_kernel(sum, variance);
#else
#error "SPECULAR_AA: a value without code here"
#endif
    return roughness_from_alpha2(alpha2 + min(kernel, threshold));
#endif
}
#else
// shading=compute: derivatives from the neighbouring pixels' rays.
// Forward difference of the normal (or reflection vector) to the next pixel in x and y; zero
// across a silhouette.
void surface_differences(vec2 p, vec2 size, vec3 n, vec3 v, out vec3 dn_dx, out vec3 dn_dy, out vec3 dr_dx, out vec3 dr_dy) {
    int id;
    vec3 nx, vx, ny, vy;
    vec3 r = reflect(-v, n);
    dn_dx = dn_dy = dr_dx = dr_dy = vec3(0.0);
    if (surface_at(p + vec2(1.0, 0.0), size, id, nx, vx)) {
        dn_dx = nx - n;
        dr_dx = reflect(-vx, nx) - r;
    }
    if (surface_at(p + vec2(0.0, 1.0), size, id, ny, vy)) {
        dn_dy = ny - n;
        dr_dy = reflect(-vy, ny) - r;
    }
}

float specular_aa_roughness(float roughness, vec3 n, vec3 v, vec2 p, vec2 size, float variance, float threshold) {
#if SPECULAR_AA == SPECULAR_AA_OFF
    return roughness;
#else
    float alpha2 = roughness * roughness * roughness * roughness;
    vec3 dn_dx, dn_dy, dr_dx, dr_dy;
#if SPECULAR_AA == SPECULAR_AA_TOKUYOSHI
    surface_differences(p, size, n, v, dn_dx, dn_dy, dr_dx, dr_dy);
    float kernel = tokuyoshi_kernel(dn_dx, dn_dy, variance);
#elif SPECULAR_AA == SPECULAR_AA_RJUMP
    surface_differences(p, size, n, v, dn_dx, dn_dy, dr_dx, dr_dy);
    float kernel = rjump_kernel(dr_dx, dr_dy, variance);
#elif SPECULAR_AA == SPECULAR_AA_TOKSVIG
    // Four sub-pixel rays at ±¼ pixel (a miss keeps the centre's normal).
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            int id;
            vec3 ni, vi;
            sum += surface_at(p + (vec2(i, j) - 0.5) * 0.5, size, id, ni, vi) ? ni : n;
        }
    float kernel = toksvig_kernel(sum, variance);
#else
#error "SPECULAR_AA: a value without code here"
#endif
    return roughness_from_alpha2(alpha2 + min(kernel, threshold));
#endif
}

#endif
#endif
