// Image files at the edges of the harness: OpenEXR and PNG through their own libraries, other
// formats through OpenImageIO, loaded only when such a file is read (image_formats.h). In memory every image is a cv::Mat,
// CV_32FC3 in RGB order (not OpenCV's BGR): linear radiance for HDR files (EXR, Radiance HDR,
// float TIFF), sRGB-encoded values in [0,1] for 8/16-bit files (PNG, JPEG...).
// Bad input throws iblcheck::InputError whose message starts with the file path.
#pragma once
#include <string>

#include <opencv2/core.hpp>

namespace iblcheck {

struct LoadedImage {
    cv::Mat pixels;        // CV_32FC3, RGB
    bool hdr = false;      // true: linear float data (EXR/HDR/float TIFF); false: sRGB in [0,1]
    int file_channels = 0; // channels in the file before dropping alpha / expanding grey
    bool has_alpha() const { return file_channels == 2 || file_channels == 4; }
    std::string path;
};

// Reads an image; grey becomes 3 equal channels, alpha (4th channel, or 2nd of grey+alpha) is
// dropped after reading the colour unassociated (as stored: not multiplied by alpha, which is
// what NVIDIA's FLIP tool scores). Throws InputError: missing file, unreadable/corrupt data, unsupported channel count.
LoadedImage read_image(const std::string& path);

// Writes float data as EXR (half is not used: float keeps error maps exact). 1 or 3 channels.
void write_exr(const std::string& path, const cv::Mat& mat);
// Writes float data as half-float EXR (ZIP): a third of the size, for images people look at (the
// report's exposure control); values above 65504 become 65504 (half's largest finite value).
void write_exr_half(const std::string& path, const cv::Mat& mat);
// Writes 8-bit PNG from float values in [0,1] (clamped, rounded), 1 or 3 channels, RGB order.
void write_png(const std::string& path, const cv::Mat& mat);

// NaN/Inf values of a float image: how many, and the first pixel (row-major) holding one.
struct NonFinite {
    size_t count = 0;
    int x = -1, y = -1;
    std::string describe() const; // "N non-finite value(s) (NaN/Inf), first at x=X, y=Y"
};
NonFinite find_non_finite(const cv::Mat& mat);
// NaN/Inf check: throws InputError "<path>: N non-finite value(s) (NaN/Inf), first at x=X, y=Y".
void check_finite(const cv::Mat& mat, const std::string& path);
// Number of negative channel values (HDR radiance must be >= 0).
size_t count_negative(const cv::Mat& mat);
// Clamps negative values to 0 in place; returns how many were changed.
size_t clamp_negative(cv::Mat& mat);
// Throws InputError naming both files when the sizes differ.
void check_same_size(const cv::Mat& a, const cv::Mat& b, const std::string& path_a, const std::string& path_b);

} // namespace iblcheck
