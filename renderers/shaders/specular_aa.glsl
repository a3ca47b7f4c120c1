// Specular anti-aliasing for low roughness (option specular_aa). SPECULAR_AA: 0 off.
// The hook every shading pass calls; the variants (tokuyoshi, rjump, toksvig) arrive with the
// temporal suite.
#ifndef IBLCHECK_SPECULAR_AA_GLSL
#define IBLCHECK_SPECULAR_AA_GLSL
#ifndef SPECULAR_AA
#define SPECULAR_AA 0
#endif
float specular_aa_roughness(float roughness, vec3 n, vec2 pixel, vec2 size, float variance, float threshold) {
    return roughness;
}
#endif
