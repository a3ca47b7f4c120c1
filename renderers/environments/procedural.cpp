// Procedural environments. Everything is a closed-form function of the pixel index: no random
// numbers, so the images (and their content hashes) are identical on every machine.
#include "renderers/environments/procedural.h"

#include <algorithm>
#include <cmath>

#include "renderers/environments/environment.h"

namespace iblcheck::procedural {

namespace {
constexpr double kPi = 3.14159265358979323846;

double smoothstep(double e0, double e1, double x) {
    double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

// Overlap length of [a0, a1) and [b0, b1).
double overlap(double a0, double a1, double b0, double b1) { return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)); }

struct RectLight {
    double u0, u1, v0, v1; // in [0,1] uv (no wrap)
    double rgb[3];
};

// A few rectangular (in uv) area lights, 10–50, warm key / cool fill / top strip / rim / low kicker.
const RectLight kStudioLights[] = {
    {0.10, 0.18, 0.20, 0.34, {40.0, 36.0, 30.0}}, // key: front-left, above (reflects on the upper left)
    {0.80, 0.90, 0.36, 0.48, {9.0, 11.0, 14.0}},  // fill: front-right, near the horizon, cool
    {0.40, 0.60, 0.02, 0.07, {20.0, 20.0, 20.0}}, // top strip, almost overhead
    {0.44, 0.49, 0.30, 0.46, {50.0, 48.0, 45.0}}, // rim: behind the sphere (grazing reflections)
    {0.58, 0.70, 0.55, 0.60, {15.0, 12.0, 10.0}}, // low kicker below the horizon, behind
};
} // namespace

cv::Mat make_studio(int width, int height) {
    cv::Mat img(height, width, CV_32FC3);
    for (int j = 0; j < height; ++j) {
        double v = (j + 0.5) / height;
        double cos_t = std::cos(v * kPi); // d.y
        for (int i = 0; i < width; ++i) {
            double u = (i + 0.5) / width;
            double phi = (u - 0.5) * 2 * kPi;
            // Backdrop: ceiling 0.2 (zenith) -> 0.1 (horizon); floor 0.06 -> 0.04 (nadir); smooth seam.
            double ceil_w = smoothstep(-0.03, 0.03, cos_t);
            double ceiling = 0.10 + 0.10 * std::max(0.0, cos_t);
            double floor = 0.06 - 0.02 * std::max(0.0, -cos_t);
            double base = ceil_w * ceiling + (1 - ceil_w) * floor;
            // Gentle azimuthal colour variation (walls of slightly different tint).
            double rgb[3] = {base * (1.0 + 0.25 * std::cos(phi - 0.5)), base * (1.0 + 0.10 * std::cos(phi + 1.0)),
                             base * (1.0 + 0.25 * std::cos(phi + 2.5))};
            // Lights, anti-aliased by the exact pixel-area overlap of the uv rectangle.
            double x0 = double(i) / width, x1 = double(i + 1) / width;
            double y0 = double(j) / height, y1 = double(j + 1) / height;
            for (const auto& L : kStudioLights) {
                double cov = std::min(1.0, overlap(x0, x1, L.u0, L.u1) * overlap(y0, y1, L.v0, L.v1) * width * height);
                if (cov <= 0) continue;
                for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] * (1 - cov) + L.rgb[c] * cov;
            }
            auto& px = img.at<cv::Vec3f>(j, i);
            for (int c = 0; c < 3; ++c) px[c] = float(rgb[c]);
        }
    }
    return img;
}

cv::Mat make_sky_sun(int width, int height) {
    cv::Mat img(height, width, CV_32FC3);
    double el = kSunElevationDeg * kPi / 180, az = kSunAzimuthDeg * kPi / 180;
    double sun[3] = {std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az)};
    double cos_r = std::cos(kSunRadiusDeg * kPi / 180);
    double cos_near = std::cos((kSunRadiusDeg + 2.0 * 360.0 / width) * kPi / 180); // within ~2 px of the disk
    auto sky = [&](const double d[3], double rgb[3]) {
        double y = d[1];
        double t = std::sqrt(std::max(0.0, y));
        double sky_w = smoothstep(-0.01, 0.01, y); // ~1 deg blend at the horizon
        for (int c = 0; c < 3; ++c) {
            double s = kSkyHorizon[c] + (kSkyZenith[c] - kSkyHorizon[c]) * t;
            double g = kGround[c] * (1.0 - 0.3 * std::max(0.0, -y));
            rgb[c] = sky_w * s + (1 - sky_w) * g;
        }
    };
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) {
            float d[3];
            uv_to_direction(float((i + 0.5) / width), float((j + 0.5) / height), d);
            double dd[3] = {d[0], d[1], d[2]};
            double rgb[3];
            sky(dd, rgb);
            double cs = dd[0] * sun[0] + dd[1] * sun[1] + dd[2] * sun[2];
            if (cs > cos_near) {
                // Sun disk coverage by 8x8 supersampling of the pixel (deterministic).
                int inside = 0;
                for (int sy = 0; sy < 8; ++sy)
                    for (int sx = 0; sx < 8; ++sx) {
                        float ds[3];
                        uv_to_direction(float((i + (sx + 0.5) / 8) / width), float((j + (sy + 0.5) / 8) / height), ds);
                        if (ds[0] * sun[0] + ds[1] * sun[1] + ds[2] * sun[2] >= cos_r) ++inside;
                    }
                double cov = inside / 64.0;
                for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] * (1 - cov) + kSunRadiance[c] * cov;
            }
            auto& px = img.at<cv::Vec3f>(j, i);
            for (int c = 0; c < 3; ++c) px[c] = float(rgb[c]);
        }
    }
    return img;
}

} // namespace iblcheck::procedural
