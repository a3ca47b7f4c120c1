// The first 9 real spherical harmonics (bands 0–2), once for the projection (sh9_project.comp)
// and the evaluation of the irradiance it writes: Σ c_lm Y_lm(n) = E(n)/π.
// Constants (Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment
// Maps", eq. 3), rounded to 6 digits as every renderer that cites them does:
//   Y00 = 1/(2√π) = 0.282095      Y1m = √(3/(4π)) = 0.488603
//   Y2{-2,-1,1} = √(15/(4π)) = 1.092548   Y20 = √(5/(16π)) = 0.315392   Y22 = √(15/(16π)) = 0.546274
#ifndef IBLCHECK_SH9_GLSL
#define IBLCHECK_SH9_GLSL
const float SH_Y00 = 0.282095;
const float SH_Y1 = 0.488603;
const float SH_Y2_XY = 1.092548;
const float SH_Y20 = 0.315392;
const float SH_Y22 = 0.546274;

// Order: 00, 1-1 (y), 10 (z), 11 (x), 2-2 (xy), 2-1 (yz), 20, 21 (xz), 22 (x² − y²).
void sh9_basis(vec3 d, out float y[9]) {
    y[0] = SH_Y00;
    y[1] = SH_Y1 * d.y;
    y[2] = SH_Y1 * d.z;
    y[3] = SH_Y1 * d.x;
    y[4] = SH_Y2_XY * d.x * d.y;
    y[5] = SH_Y2_XY * d.y * d.z;
    y[6] = SH_Y20 * (3.0 * d.z * d.z - 1.0);
    y[7] = SH_Y2_XY * d.x * d.z;
    y[8] = SH_Y22 * (d.x * d.x - d.y * d.y);
}

vec3 sh9_eval(vec4 c[10], vec3 d) {
    float y[9];
    sh9_basis(d, y);
    vec3 r = c[0].rgb * y[0];
    r += c[1].rgb * y[1] + c[2].rgb * y[2] + c[3].rgb * y[3];
    r += c[4].rgb * y[4] + c[5].rgb * y[5];
    r += c[6].rgb * y[6] + c[7].rgb * y[7];
    r += c[8].rgb * y[8];
    return max(r, vec3(0.0));
}
#endif
