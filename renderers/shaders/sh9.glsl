// Evaluates the SH9 irradiance written by sh9_project.comp: Σ c_lm Y_lm(n) = E(n)/π.
#ifndef IBLCHECK_SH9_GLSL
#define IBLCHECK_SH9_GLSL
vec3 sh9_eval(vec4 c[10], vec3 d) {
    vec3 r = c[0].rgb * 0.282095;
    r += c[1].rgb * (0.488603 * d.y) + c[2].rgb * (0.488603 * d.z) + c[3].rgb * (0.488603 * d.x);
    r += c[4].rgb * (1.092548 * d.x * d.y) + c[5].rgb * (1.092548 * d.y * d.z);
    r += c[6].rgb * (0.315392 * (3.0 * d.z * d.z - 1.0)) + c[7].rgb * (1.092548 * d.x * d.z);
    r += c[8].rgb * (0.546274 * (d.x * d.x - d.y * d.y));
    return max(r, vec3(0.0));
}
#endif
