// Procedural environments (deterministic, no randomness): `studio` and `sky_sun`, 1024x512.
// Internal to iblcheck_scenes; load_environment() is the public entry point. The constants are
// exposed so tests (and the report) can name the sun's direction, size and radiance.
#pragma once
#include <opencv2/core.hpp>

namespace iblcheck::procedural {

inline constexpr int kWidth = 1024, kHeight = 512;

// sky_sun: the sun's centre direction (unit, world Y-up), angular radius and radiance (RGB).
// Elevation 35 deg, azimuth 150 deg from -Z towards +X (u = 0.9167, v = 0.3056): in front of and
// above the default camera (which looks from +Z), so it reflects on the spheres' upper-right side.
inline constexpr double kSunElevationDeg = 35.0;
inline constexpr double kSunAzimuthDeg = 150.0; // phi of the equirect convention
inline constexpr double kSunRadiusDeg = 1.25;
inline constexpr double kSkyZenith[3] = {0.20, 0.35, 0.75};
inline constexpr double kSkyHorizon[3] = {0.75, 0.80, 0.90};
inline constexpr double kGround[3] = {0.10, 0.09, 0.08};
// 1e5 x the sky's mean luminance (about 0.5).
inline constexpr double kSunRadiance[3] = {5.0e4, 4.8e4, 4.5e4};

cv::Mat make_studio(int width = kWidth, int height = kHeight);
cv::Mat make_sky_sun(int width = kWidth, int height = kHeight);

} // namespace iblcheck::procedural
