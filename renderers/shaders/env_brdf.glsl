// The split sum's second factor (option env_brdf, define ENV_BRDF).
#ifndef IBLCHECK_ENV_BRDF_GLSL
#define IBLCHECK_ENV_BRDF_GLSL
#include "precision.glsl"
#ifndef ENV_BRDF
#error "ENV_BRDF is set from the option table (renderers/option_table.cpp)"
#endif

// EnvBRDFApprox: Karis 2014, "Physically Based Shading on Mobile" (after Lazarov 2013, "Getting
// More Physical in Call of Duty: Black Ops II"). An analytic fit of (A, B); the constants are the
// published ones and are the knob the gate test perturbs (ENV_BRDF_APPROX_C0/C1).
#ifndef ENV_BRDF_APPROX_C0
#define ENV_BRDF_APPROX_C0 vec4(-1.0, -0.0275, -0.572, 0.022)
#endif
#ifndef ENV_BRDF_APPROX_C1
#define ENV_BRDF_APPROX_C1 vec4(1.0, 0.0425, 1.04, -0.04)
#endif
hvec2 env_brdf_approx(hfloat roughness, hfloat n_dot_v) {
    hvec4 r = hfloat(roughness) * hvec4(ENV_BRDF_APPROX_C0) + hvec4(ENV_BRDF_APPROX_C1);
    hfloat a004 = min(r.x * r.x, hfloat(exp2(-9.28 * float(n_dot_v)))) * r.x + r.y;
    return hvec2(-1.04, 1.04) * a004 + r.zw;
}
// Texture coordinate of (n·v, r) in the DFG LUT, whose texel i holds i/(size − 1) (dfg_lut.comp).
vec2 dfg_lut_uv(float n_dot_v, float roughness, float size) {
    return (vec2(n_dot_v, roughness) * (size - 1.0) + 0.5) / size;
}
#endif
