#version 460
// Pass 4 (env_brdf=lut): the split sum's second factor (Karis 2013, eq. 3, right), tabulated over
// (n·v, r): with F = F0 + (1 − F0)Fc, ∫ f cos = F0·A + B where
//   A = ∫ (1 − Fc) V 4 (v·h)(n·l)/(n·h),   B = ∫ Fc V 4 (v·h)(n·l)/(n·h),   Fc = (1 − v·h)^5,
// estimated with GGX samples (pdf D(n·h)) and the model's height-correlated V. Stored RG16F;
// texel (i, j) holds n·v = i/(size − 1), r = j/(size − 1), so the table's end points are exact
// (r = 1 is on a texel centre, not half a texel inside); lookups use dfg_lut_uv() (env_brdf.glsl).
#include "common.glsl"
#include "brdf.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rg16f) uniform writeonly image2D lut;
layout(push_constant) uniform Push { uint size; uint sample_count; } pc;

void main() {
    uvec2 t = gl_GlobalInvocationID.xy;
    if (t.x >= pc.size || t.y >= pc.size) return;
    float n_dot_v = max(float(t.x) / float(pc.size - 1u), 1e-4);
    float r = float(t.y) / float(pc.size - 1u);
    float alpha = max(r * r, 1e-4);
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 v = vec3(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    float a = 0.0, b = 0.0;
    for (uint i = 0u; i < pc.sample_count; ++i) {
        vec3 h = importance_sample_ggx(hammersley(i, pc.sample_count), alpha, n);
        vec3 l = normalize(2.0 * dot(v, h) * h - v);
        float n_dot_l = l.z, n_dot_h = max(h.z, 0.0), v_dot_h = max(dot(v, h), 0.0);
        if (n_dot_l <= 0.0) continue;
        float g_vis = v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha) * 4.0 * v_dot_h * n_dot_l / max(n_dot_h, 1e-8);
        float x = 1.0 - v_dot_h;
        float fc = x * x * x * x * x;
        a += (1.0 - fc) * g_vis;
        b += fc * g_vis;
    }
    imageStore(lut, ivec2(t), vec4(a, b, 0.0, 0.0) / float(pc.sample_count));
}
