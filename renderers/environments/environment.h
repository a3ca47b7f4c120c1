// Environments shared by all methods: a linear-HDR equirectangular image.
//
// Direction convention (GLSL mirror: direction_to_equirect_uv in renderers/shaders/common.glsl and its
// inverse equirect_decode in env_layout.glsl). World is Y-up.
//   u = 0.5 + atan2(d.x, −d.z) / 2π,   v = acos(d.y) / π        (u, v in [0,1], v = 0 is straight up)
//   pixel centre (i + 0.5, j + 0.5) ↔ (u·W, v·H); bilinear, wrapping in u, clamped in v.
//   inverse: φ = (u − 0.5)·2π, θ = v·π, d = (sin θ sin φ, cos θ, −sin θ cos φ)
// So −Z (the view direction of the default camera, looking from +Z) is the panorama's centre column.
//
// Specs: `constant:R,G,B` (or `constant:V`), `studio`, `sky_sun`, `blender:NAME` (Debian
// blender-data's studio-light panoramas, see scripts/setup.sh), or a path to an .exr/.hdr file.
// Files: negatives (lossy EXR has ≈ −0.004) are clamped to 0 and counted; NaN/Inf are an InputError.
// Radiance above 1e30 (any spec) is an InputError naming the pixel: the renderers sum it in floats.
// Sizes: constant:* is 64x32, studio and sky_sun are 1024x512 (procedural.h), files keep their size.
// Channel order of `equirect` is R, G, B (not OpenCV's BGR), as read from the file.
// Rotation (env_rotation): the panorama is turned by +rotation_deg about +Y (right-handed, so +90
// moves what was at −Z to −X); a lookup in world direction d reads the panorama at R_y(−rotation_deg)·d:
//   x' = cos(a)·x + sin(a)·z,  z' = −sin(a)·x + cos(a)·z,  a = −rotation_deg.
#pragma once
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace iblcheck {

struct Environment {
    std::string spec; // as given
    cv::Mat equirect; // CV_32FC3, linear, width = 2·height
    long negatives_clamped = 0;
    std::string content_hash; // hex FNV-1a-64 of the pixel data, for provenance
    std::string source_path;  // file it came from, empty for procedural
    // Rotation about +Y in degrees applied on lookup (option env_rotation); 0 by default.
    float rotation_deg = 0;
};

struct EnvironmentInfo {
    std::string spec;
    std::string description;
};
std::vector<EnvironmentInfo> environment_catalog();

// Throws UsageError for an unknown spec (listing valid ones), InputError for a bad file.
Environment load_environment(const std::string& spec);

// Whether `spec` is a path to a file (not a built-in environment such as studio or blender:city).
bool is_environment_file(const std::string& spec);
// The environment's stable name, as test names, golden keys and sidecars give it (never a machine's
// absolute path): a built-in spec as written; a file by `name` when one is given, else its file name
// (city.exr: a file name has an extension, so it never takes a built-in environment's key).
std::string environment_label(const std::string& spec, const std::string& name = "");

// Hex FNV-1a-64 of an image's bytes, row by row (Environment::content_hash).
std::string fnv1a64_hex(const cv::Mat& m);

// Direction ↔ equirect helpers (the convention above).
void direction_to_uv(const float d[3], float& u, float& v);
void uv_to_direction(float u, float v, float d[3]);
// Bilinear lookup at (u, v) of RGB float rows (`stride` floats apart), wrapping in u, clamped in v.
void bilinear_equirect(const float* data, int width, int height, size_t stride, double u, double v, double rgb[3]);
// Bilinear lookup of the equirect in direction d (unit), honouring env.rotation_deg.
void sample_bilinear(const Environment& env, const float d[3], float rgb[3]);

} // namespace iblcheck
