// Layout of the prefiltered radiance (option env_layout, define ENV_LAYOUT): the cubemap, or one 2D
// texture, octahedral or lat-long (seed 001: 2D textures batch into texture arrays where GLES 3.1
// has no cube arrays). Host side, sizes and a CPU copy of these mappings:
// renderers/mobile/env_layout.h.
//
// A 2D level of w×h texels is a 1-texel border around an inner (w−2)×(h−2) map; a border texel
// holds the inner texel across the seam (layout_gutter_source), so bilinear filtering never
// reads across a seam. The border makes each level's UVs its own, so a lookup samples the two
// levels around the lod with their own UVs and blends them (sample_env_2d): two bilinear fetches,
// as hardware trilinear makes.
#ifndef IBLCHECK_ENV_LAYOUT_GLSL
#define IBLCHECK_ENV_LAYOUT_GLSL
#include "common.glsl"
#ifndef ENV_LAYOUT
#error "ENV_LAYOUT is set from the option table (renderers/option_table.cpp)"
#endif

#if ENV_LAYOUT == ENV_LAYOUT_CUBE
#define ENV_SAMPLER samplerCube
#define ENV_IMAGE image2DArray
#else
#define ENV_SAMPLER sampler2D
#define ENV_IMAGE image2D
#endif

// Octahedral map (Praun & Hoppe 2003; Cigolle et al. 2014, "A Survey of Efficient Representations
// for Independent Unit Vectors", listing 1): +Z at the centre, −Z at the four corners.
vec2 sign_not_zero(vec2 v) { return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }
vec2 octahedral_encode(vec3 d) {
    vec2 p = d.xy / (abs(d.x) + abs(d.y) + abs(d.z));
    if (d.z < 0.0) p = (1.0 - abs(p.yx)) * sign_not_zero(p);
    return p * 0.5 + 0.5;
}
vec3 octahedral_decode(vec2 uv) {
    vec2 p = uv * 2.0 - 1.0;
    vec3 d = vec3(p, 1.0 - abs(p.x) - abs(p.y));
    if (d.z < 0.0) d.xy = (1.0 - abs(d.yx)) * sign_not_zero(d.xy);
    return normalize(d);
}
// Inverse of direction_to_equirect_uv (common.glsl): u = 0.5 + atan2(x, −z)/2π, v = acos(y)/π.
vec3 equirect_decode(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * PI, theta = uv.y * PI;
    return vec3(sin(phi) * sin(theta), cos(theta), -cos(phi) * sin(theta));
}

#if ENV_LAYOUT != ENV_LAYOUT_CUBE
// Level size of a 2D layout from its width: octahedral square, equirect 2:1.
uvec2 layout_level_size(uint width) {
#if ENV_LAYOUT == ENV_LAYOUT_EQUIRECT
    return uvec2(width, max(width / 2u, 1u));
#elif ENV_LAYOUT == ENV_LAYOUT_OCTAHEDRAL
    return uvec2(width);
#endif
}

// The inner texel that border texel j (−1..n) copies (env_layout.h, gutter_source).
ivec2 layout_gutter_source(ivec2 j, ivec2 n) {
#if ENV_LAYOUT == ENV_LAYOUT_OCTAHEDRAL
    // Each edge folds onto itself about its midpoint; a corner lands on the opposite corner.
    if (j.x < 0) j = ivec2(0, n.y - 1 - j.y);
    else if (j.x >= n.x) j = ivec2(n.x - 1, n.y - 1 - j.y);
    if (j.y < 0) j = ivec2(n.x - 1 - j.x, 0);
    else if (j.y >= n.y) j = ivec2(n.x - 1 - j.x, n.y - 1);
#elif ENV_LAYOUT == ENV_LAYOUT_EQUIRECT
    // Beyond a pole: the pole row half a turn around; longitude wraps.
    if (j.y < 0) j = ivec2(j.x + n.x / 2, 0);
    else if (j.y >= n.y) j = ivec2(j.x + n.x / 2, n.y - 1);
    j.x = ((j.x % n.x) + n.x) % n.x;
#endif
    return j;
}

// Inner-map coordinates in [0, 1]² of a direction (need not be unit).
vec2 layout_inner_uv(vec3 d) {
#if ENV_LAYOUT == ENV_LAYOUT_OCTAHEDRAL
    return octahedral_encode(d);
#elif ENV_LAYOUT == ENV_LAYOUT_EQUIRECT
    return direction_to_equirect_uv(normalize(d));
#endif
}

// The texel a 2D level's texel t copies (itself inside the border), and its direction.
ivec2 layout_source_texel(uvec2 t, uvec2 size) {
    ivec2 n = ivec2(size) - 2;
    return layout_gutter_source(ivec2(t) - 1, n) + 1;
}
vec3 layout_texel_direction(ivec2 source_texel, uvec2 size) {
    vec2 uv = (vec2(source_texel - 1) + 0.5) / vec2(ivec2(size) - 2);
#if ENV_LAYOUT == ENV_LAYOUT_OCTAHEDRAL
    return octahedral_decode(uv);
#else
    return equirect_decode(uv);
#endif
}

// Prefiltered radiance along d at a fractional lod: level l's map is inset by its border, so
// each of the two levels is sampled at its own UV, then blended.
vec4 sample_env_2d(sampler2D s, vec3 d, float lod) {
    vec2 p = layout_inner_uv(d);
    float l0 = floor(lod);
    float l1 = min(l0 + 1.0, float(textureQueryLevels(s) - 1));
    // Level sizes from the base size: textureSize(s, lod) with a lod that differs between
    // invocations gives llvmpipe-version- and CPU-class-dependent answers.
    ivec2 base = textureSize(s, 0);
    vec2 s0 = vec2(max(base >> int(l0), ivec2(1))), s1 = vec2(max(base >> int(l1), ivec2(1)));
    vec4 a = textureLod(s, (1.0 + p * (s0 - 2.0)) / s0, l0);
    vec4 b = textureLod(s, (1.0 + p * (s1 - 2.0)) / s1, l1);
    return mix(a, b, lod - l0);
}
#endif

// How the shading pass reads the prefiltered chain. A macro, so the cube's code is exactly the
// plain cube lookup it always was.
#if ENV_LAYOUT == ENV_LAYOUT_CUBE
#define SAMPLE_ENV(s, d, lod) textureLod(s, d, lod)
#else
#define SAMPLE_ENV(s, d, lod) sample_env_2d(s, d, lod)
#endif

#endif
