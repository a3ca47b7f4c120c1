// Shared constants and helpers: low-discrepancy points, hashing, direction conventions.
// Conventions mirror renderers/environments/environment.h (equirect) and the Vulkan cube layout.
#ifndef IBLCHECK_COMMON_GLSL
#define IBLCHECK_COMMON_GLSL

const float PI = 3.14159265358979323846;

// Van der Corput radical inverse in base 2 and the Hammersley point set (Hammersley 1964).
float radical_inverse_vdc(uint bits) {
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064365386963e-10;
}
vec2 hammersley(uint i, uint n) { return vec2(float(i) / float(n), radical_inverse_vdc(i)); }

// PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering"): a per-texel / per-pixel
// random rotation of the point set, deterministic for a given coordinate.
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
vec2 random_rotation(uvec3 p) {
    uint h = pcg_hash(p.x ^ pcg_hash(p.y ^ pcg_hash(p.z)));
    uint h2 = pcg_hash(h);
    return vec2(float(h >> 8u), float(h2 >> 8u)) * (1.0 / 16777216.0);
}

// Equirect convention (environment.h): u = 0.5 + atan2(d.x, −d.z)/2π, v = acos(d.y)/π.
vec2 direction_to_equirect_uv(vec3 d) {
    return vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

// Vulkan cube layout: layer 0 +X, 1 −X, 2 +Y, 3 −Y, 4 +Z, 5 −Z; (s, t) in [−1, 1], t down.
vec3 cube_direction(uint face, vec2 st) {
    float s = st.x, t = st.y;
    vec3 d;
    if (face == 0u) d = vec3(1.0, -t, -s);
    else if (face == 1u) d = vec3(-1.0, -t, s);
    else if (face == 2u) d = vec3(s, 1.0, t);
    else if (face == 3u) d = vec3(s, -1.0, -t);
    else if (face == 4u) d = vec3(s, -t, 1.0);
    else d = vec3(-s, -t, -1.0);
    return normalize(d);
}
// Texel centre of (x, y) on a face of `size` texels → direction.
vec3 cube_texel_direction(uvec3 texel, uint size) {
    vec2 st = (vec2(texel.xy) + 0.5) / float(size) * 2.0 - 1.0;
    return cube_direction(texel.z, st);
}
// Solid angle of a cube texel (exact, from the area integral of the projected square:
// Ω = Σ± atan(xy / sqrt(x² + y² + 1)) at its corners).
float cube_texel_solid_angle(uvec2 xy, uint size) {
    float inv = 1.0 / float(size);
    vec2 a = vec2(xy) * 2.0 * inv - 1.0;
    vec2 b = a + 2.0 * inv;
    #define AREA(x, y) atan((x) * (y), sqrt((x) * (x) + (y) * (y) + 1.0))
    return AREA(a.x, a.y) - AREA(a.x, b.y) - AREA(b.x, a.y) + AREA(b.x, b.y);
    #undef AREA
}

// Rotation about +Y by `deg` degrees: the environment turns by +deg, so a world direction is looked
// up at R_y(−deg)·d (environment.h: env_rotation).
vec3 rotate_y(vec3 d, float deg) {
    float a = radians(deg), c = cos(a), s = sin(a);
    return vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

#endif
