// Constants of FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating
// Images", HPG 2020) and HDR-FLIP (Andersson et al. 2021, "Visualizing Errors in Rendered High
// Dynamic Range Images", EG 2021), named after the papers. All float32: the reference tool
// (NVlabs/flip v1.6) computes in single precision and our results must agree with it per pixel.
#pragma once

namespace iblcheck::flip {

inline constexpr float kPi = 3.14159265358979f;

// Default viewing condition: 0.7 m from a 0.7 m wide 3840-pixel monitor (FLIP paper, Sec. 5):
// ppd = distance * (resolution / width) * pi / 180, evaluated in float like the tool.
inline constexpr float kDefaultPpd = 0.7f * (3840.0f / 0.7f) * (kPi / 180.0f);

// Colour pipeline (FLIP paper, Sec. 4.1).
inline constexpr float kQc = 0.7f;  // exponent compressing the HyAB colour distance (Eq. 6)
inline constexpr float kPc = 0.4f;  // break point of the error redistribution (Eq. 7), fraction of cmax
inline constexpr float kPt = 0.95f; // error value mapped to at the break point (Eq. 7)

// Feature pipeline (FLIP paper, Sec. 4.2).
inline constexpr float kW = 0.082f; // feature-filter width in degrees; std dev = 0.5 * w * ppd
inline constexpr float kQf = 0.5f;  // exponent of the feature difference (Eq. 9)

// Contrast sensitivity functions as sums of Gaussians in the frequency domain (FLIP paper,
// Eq. 2 and Table 1): per opponent channel (achromatic A / Y, red-green RG / Cx, blue-yellow
// BY / Cz). Only the blue-yellow CSF has a second Gaussian (a2 = 0 elsewhere).
struct CsfGaussian {
    float a1, b1, a2, b2;
};
inline constexpr CsfGaussian kCsfY{1.0f, 0.0047f, 0.0f, 1.0e-5f};
inline constexpr CsfGaussian kCsfCx{1.0f, 0.0053f, 0.0f, 1.0e-5f};
inline constexpr CsfGaussian kCsfCz{34.1f, 0.04f, 13.5f, 0.025f};

// D65 reference white in XYZ and its reciprocal, as the tool spells them (used by YCxCz and
// CIELab, FLIP paper Sec. 4.1).
inline constexpr float kD65[3] = {0.950428545f, 1.000000000f, 1.088900371f};
inline constexpr float kInvD65[3] = {1.052156925f, 1.000000000f, 0.918357670f};

// HDR-FLIP (HDR-FLIP paper, Sec. 4): the automatic exposure range maps the reference's largest
// luminance, and its median luminance, to this tone-mapped value.
inline constexpr float kHdrTargetToneMapped = 0.85f;

} // namespace iblcheck::flip
