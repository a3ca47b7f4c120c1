// What a player sees (issue 29): a render's linear radiance as a phone displays it, step by step:
//   1. the render target's rounding: the HDR scene colour is stored in the target format before
//      the tonemapping pass reads it (rgba32f: as rendered; rgba16f: IEEE binary16; r11g11b10f:
//      unsigned 11/11/10-bit floats, 6/6/5-bit mantissas, no sign),
//   2. the exposure: × 2^EV (applied in the tonemapping pass, after the target),
//   3. the tonemapper, to [0, 1]:
//      - aces_narkowicz: Krzysztof Narkowicz's luminance-only fit of ACES's RRT+ODT ("ACES Filmic
//        Tone Mapping Curve", 2016), x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), with the 0.6 input
//        scale he gives for the original ACES curve: exactly the curve HDR-FLIP and the harness's
//        linear SSIM use (metrics/flip/tone_mappers.h). Not Stephen Hill's RRT/ODT matrix fit
//        ("ACESFitted"). An engine that calls his curve without the 0.6 ("1 maps to ~0.8") is
//        this one at exposure log2(1/0.6) = +0.737 EV;
//      - pbr_neutral: the Khronos PBR Neutral tone mapper, from its specification
//        (KhronosGroup/ToneMapping, PBR_Neutral/README.md): F90 = 0.04, Ks = 0.8 − F90, Kd = 0.15,
//   4. the sRGB OETF (IEC 61966-2-1),
//   5. the quantisation: srgb8, an 8-bit UNORM swapchain (round to the nearest of 256 levels), or
//      none.
// The result is sRGB-encoded display values in [0, 1]: what LDR-FLIP, SSIM and PSNR take.
#pragma once
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace iblcheck {

enum class DisplayTonemap { aces_narkowicz, pbr_neutral };
enum class DisplayQuantize { srgb8, none };
enum class RenderTarget { rgba32f, rgba16f, r11g11b10f };

struct DisplaySpace {
    DisplayTonemap tonemap = DisplayTonemap::aces_narkowicz;
    double exposure_ev = 0;
    DisplayQuantize quantize = DisplayQuantize::srgb8;
    RenderTarget target = RenderTarget::rgba32f;
};

const char* tonemap_name(DisplayTonemap t);
const char* quantize_name(DisplayQuantize q);
const char* target_name(RenderTarget t);
// nullopt for an unknown name (the caller says where it came from).
std::optional<DisplayTonemap> parse_tonemap(std::string_view name);
std::optional<DisplayQuantize> parse_quantize(std::string_view name);
std::optional<RenderTarget> parse_target(std::string_view name);
// Exposures beyond this many stops take every float pixel to black or white.
inline constexpr double kMaxDisplayExposure = 64;

// {"tonemap", "exposure", "quantize", "target"}: how results name the space.
nlohmann::json display_json(const DisplaySpace& d);
// "pbr_neutral_0ev_srgb8_r11g11b10f": the space in a test's name.
std::string display_label(const DisplaySpace& d);

// --- the steps, one channel or pixel at a time ---
// RGBA16F: round to nearest even at binary16's precision (10-bit mantissa, subnormals from 2^-24);
// beyond 65504 saturates to 65504 (as R11G11B10F's rule below; round-to-nearest would store +inf,
// which every tonemapper here maps to white, and PBR Neutral to NaN).
float round_to_half(float v);
// R11G11B10F's channels (Vulkan "Unsigned 11-Bit/10-Bit Floating-Point Numbers"): 5-bit exponent
// (bias 15), 6-bit (R, G) or 5-bit (B) mantissa, no sign; negative values become 0 and finite
// values above the largest (65024; 64512) become it; round to nearest even.
float round_to_uf11(float v);
float round_to_uf10(float v);
void round_to_target(RenderTarget t, float& r, float& g, float& b);
float expose(float v, double exposure_ev);
float tonemap_aces_narkowicz(float v); // one channel, clamped to [0, 1]
void tonemap_pbr_neutral(float& r, float& g, float& b);
float srgb_oetf(float linear); // clamped to [0, 1] first
float quantize_8bit(float v);  // round(v · 255) / 255

// The whole transform of one linear pixel, and of an image (CV_32FC3 linear -> CV_32FC3 display
// sRGB in [0, 1]).
void to_display(const DisplaySpace& d, float& r, float& g, float& b);
cv::Mat to_display(const cv::Mat& linear, const DisplaySpace& d);

} // namespace iblcheck
