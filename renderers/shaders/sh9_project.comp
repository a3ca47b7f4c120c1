#version 460
// Pass 3: SH9 irradiance. Projects the source cube (one mip, every texel weighted by its exact
// solid angle) onto the first 9 real spherical harmonics, then convolves with the clamped cosine
// lobe (Ramamoorthi & Hanrahan 2001, eq. 8: Â0 = π, Â1 = 2π/3, Â2 = π/4) and divides by π, so
// evaluating Σ c_lm Y_lm(n) gives E(n)/π: the diffuse radiance of a white Lambertian surface.
// Also writes the mean radiance (L00·Y00), the "average brightness" UE4's mobile normalisation
// reads from the 1×1 mip.
// One workgroup; the reduction order is fixed, so the result is bit-identical run to run.
#include "common.glsl"
#include "sh9.glsl"

layout(local_size_x = 256) in;
layout(binding = 0, rgba32f) uniform readonly image2DArray source;
layout(binding = 1, std430) writeonly buffer SH { vec4 coeffs[10]; } sh; // 9 coefficients + mean
layout(push_constant) uniform Push { uint size; } pc;

shared vec3 partial[256][9];
shared float partial_w[256];

void main() {
    uint lid = gl_LocalInvocationID.x;
    vec3 acc[9];
    for (int k = 0; k < 9; ++k) acc[k] = vec3(0.0);
    float wsum = 0.0;
    uint total = pc.size * pc.size * 6u;
    for (uint i = lid; i < total; i += 256u) {
        uint face = i / (pc.size * pc.size);
        uint rem = i % (pc.size * pc.size);
        uvec3 t = uvec3(rem % pc.size, rem / pc.size, face);
        vec3 d = cube_texel_direction(t, pc.size);
        float w = cube_texel_solid_angle(t.xy, pc.size);
        vec3 c = imageLoad(source, ivec3(t)).rgb;
        float y[9];
        sh9_basis(d, y);
        for (int k = 0; k < 9; ++k) acc[k] += c * (y[k] * w);
        wsum += w;
    }
    for (int k = 0; k < 9; ++k) partial[lid][k] = acc[k];
    partial_w[lid] = wsum;
    barrier();
    for (uint s = 128u; s > 0u; s >>= 1u) {
        if (lid < s) {
            for (int k = 0; k < 9; ++k) partial[lid][k] += partial[lid + s][k];
            partial_w[lid] += partial_w[lid + s];
        }
        barrier();
    }
    if (lid == 0u) {
        // Renormalise the solid angles to exactly 4π (removes the quadrature's residual).
        float norm = 4.0 * PI / partial_w[0];
        const float a_hat[9] = float[9](PI, 2.0 * PI / 3.0, 2.0 * PI / 3.0, 2.0 * PI / 3.0,
                                        PI / 4.0, PI / 4.0, PI / 4.0, PI / 4.0, PI / 4.0);
        for (int k = 0; k < 9; ++k) sh.coeffs[k] = vec4(partial[0][k] * norm * a_hat[k] / PI, 0.0);
        sh.coeffs[9] = vec4(partial[0][0] * norm * SH_Y00, 0.0);
    }
}
