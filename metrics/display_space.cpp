#include "display_space.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "metrics/flip/color_spaces.h"
#include "metrics/flip/tone_mappers.h"

namespace iblcheck {

namespace {

// A small float format with `mantissa_bits` stored mantissa bits, exponent bias 15 (smallest
// normal 2^-14, subnormals below it) and largest finite value `largest`: the nearest value (ties
// to even), saturated at `largest`. Exact in double: scaling by powers of two loses nothing.
float round_to_small_float(float v, int mantissa_bits, float largest) {
    if (std::isnan(v) || v == 0.0f) return v; // NaN stays NaN (a render with one is refused before)
    const double a = std::fabs(double(v));
    int e = 0;
    std::frexp(a, &e);                         // a = m · 2^e, m in [0.5, 1): the leading bit is 2^(e-1)
    const int exponent = std::max(e - 1, -14); // subnormals share the smallest normal's step
    const double step = std::ldexp(1.0, exponent - mantissa_bits);
    const double rounded = std::min(std::nearbyint(a / step) * step, double(largest));
    return float(v < 0 ? -rounded : rounded);
}

struct Names {
    const char* tonemap[2] = {"aces_narkowicz", "pbr_neutral"};
    const char* quantize[2] = {"srgb8", "none"};
    const char* target[3] = {"rgba32f", "rgba16f", "r11g11b10f"};
};
constexpr Names kNames;

template <typename E, size_t N> std::optional<E> parse_name(const char* const (&names)[N], std::string_view name) {
    for (size_t i = 0; i < N; ++i)
        if (name == names[i]) return E(i);
    return std::nullopt;
}

} // namespace

const char* tonemap_name(DisplayTonemap t) { return kNames.tonemap[int(t)]; }
const char* quantize_name(DisplayQuantize q) { return kNames.quantize[int(q)]; }
const char* target_name(RenderTarget t) { return kNames.target[int(t)]; }
std::optional<DisplayTonemap> parse_tonemap(std::string_view n) { return parse_name<DisplayTonemap>(kNames.tonemap, n); }
std::optional<DisplayQuantize> parse_quantize(std::string_view n) { return parse_name<DisplayQuantize>(kNames.quantize, n); }
std::optional<RenderTarget> parse_target(std::string_view n) { return parse_name<RenderTarget>(kNames.target, n); }

nlohmann::json display_json(const DisplaySpace& d) {
    return {{"tonemap", tonemap_name(d.tonemap)},
            {"exposure", d.exposure_ev},
            {"quantize", quantize_name(d.quantize)},
            {"target", target_name(d.target)}};
}

std::string display_label(const DisplaySpace& d) {
    return fmt::format("{}_{:g}ev_{}_{}", tonemap_name(d.tonemap), d.exposure_ev, quantize_name(d.quantize),
                       target_name(d.target));
}

float round_to_half(float v) { return round_to_small_float(v, 10, 65504.0f); }
float round_to_uf11(float v) { return v < 0 ? 0.0f : round_to_small_float(v, 6, 65024.0f); }
float round_to_uf10(float v) { return v < 0 ? 0.0f : round_to_small_float(v, 5, 64512.0f); }

void round_to_target(RenderTarget t, float& r, float& g, float& b) {
    switch (t) {
    case RenderTarget::rgba32f: return;
    case RenderTarget::rgba16f: r = round_to_half(r), g = round_to_half(g), b = round_to_half(b); return;
    case RenderTarget::r11g11b10f: r = round_to_uf11(r), g = round_to_uf11(g), b = round_to_uf10(b); return;
    }
}

float expose(float v, double exposure_ev) { return float(double(v) * std::exp2(exposure_ev)); }

float tonemap_aces_narkowicz(float v) {
    const float t = flip::tone_map_channel(v, flip::kToneCoefficients[int(flip::ToneMapper::aces)]);
    return std::clamp(t, 0.0f, 1.0f);
}

// The specification's equations, with its names. Negative input (outside its domain) is taken as 0;
// input above 1e30 as 1e30 (the same white: inf would give inf · 0 = NaN in the compression).
void tonemap_pbr_neutral(float& r, float& g, float& b) {
    constexpr float F90 = 0.04f, Ks = 0.8f - F90, Kd = 0.15f, kMax = 1e30f;
    r = std::clamp(r, 0.0f, kMax), g = std::clamp(g, 0.0f, kMax), b = std::clamp(b, 0.0f, kMax);
    const float x = std::min({r, g, b});
    const float f = x <= 2 * F90 ? x - x * x / (4 * F90) : F90;
    r -= f, g -= f, b -= f;
    const float p = std::max({r, g, b});
    if (p <= Ks) return;
    const float pn = 1 - (1 - Ks) * (1 - Ks) / (p + 1 - 2 * Ks);
    const float gw = 1 / (Kd * (p - pn) + 1);
    const float s = pn / p * gw, w = pn * (1 - gw);
    r = r * s + w, g = g * s + w, b = b * s + w;
}

float srgb_oetf(float linear) { return flip::linear_to_srgb(std::clamp(linear, 0.0f, 1.0f)); }

float quantize_8bit(float v) { return std::nearbyint(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f; }

void to_display(const DisplaySpace& d, float& r, float& g, float& b) {
    round_to_target(d.target, r, g, b);
    r = expose(r, d.exposure_ev), g = expose(g, d.exposure_ev), b = expose(b, d.exposure_ev);
    if (d.tonemap == DisplayTonemap::pbr_neutral)
        tonemap_pbr_neutral(r, g, b);
    else
        r = tonemap_aces_narkowicz(r), g = tonemap_aces_narkowicz(g), b = tonemap_aces_narkowicz(b);
    r = srgb_oetf(r), g = srgb_oetf(g), b = srgb_oetf(b);
    if (d.quantize == DisplayQuantize::srgb8) r = quantize_8bit(r), g = quantize_8bit(g), b = quantize_8bit(b);
}

cv::Mat to_display(const cv::Mat& linear, const DisplaySpace& d) {
    CV_Assert(linear.type() == CV_32FC3);
    cv::Mat out(linear.size(), CV_32FC3);
    for (int y = 0; y < linear.rows; ++y) {
        const cv::Vec3f* s = linear.ptr<cv::Vec3f>(y);
        cv::Vec3f* o = out.ptr<cv::Vec3f>(y);
        for (int x = 0; x < linear.cols; ++x) {
            float r = s[x][0], g = s[x][1], b = s[x][2];
            to_display(d, r, g, b);
            o[x] = {r, g, b};
        }
    }
    return out;
}

} // namespace iblcheck
