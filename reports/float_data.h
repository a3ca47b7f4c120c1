// Linear image data for the page. The report's exposure control, heatmap colour scale and
// exceedance mask work on the float values of the EXRs the harness writes beside each PNG, not on
// the 8-bit display PNG (whose tone map is fixed: moving its exposure would band and clip).
//
// A page opened from file:// cannot read a file's bytes (fetch and canvas readback of file://
// images are cross-origin), but it can run a script. So each image becomes data/<key>.js:
//
//   iblcheckData("<key>", {"w":528,"h":96,"c":3,"enc":"f16","auto":-1.3,"max":11875,"p99":...}, "<base64>");
//
// the pixels as IEEE binary16 (row-major, channels interleaved), byte planes split (all low
// bytes, then all high bytes: the high bytes of smooth images compress well), zlib-compressed
// (the page inflates them with the browser's DecompressionStream("deflate")), base64. Sphere id
// maps are "enc":"u8" (one byte per pixel). The key is a hash of the content, so a golden shared by
// many tests (or a render bit-identical to its baseline) is written once.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace iblcheck::report {

struct FloatImageInfo {
    std::string key; // data/<key>.js
    int width = 0, height = 0, channels = 0;
    double auto_exposure = 0; // EV that brings the image's bright end into range (auto_exposure())
    double max = 0, p99 = 0;  // of the values (error maps: the colour scale)
};

// Exposure in stops such that the 99th percentile of luminance (Rec. 709) among the pixels that
// are not black reaches 0.85 after the report's tone map (the ACES curve of the display
// transform, metrics/display_transform.h); 0 for a black image. Clamped to [-20, 20], rounded to
// 0.1. The percentile, not the maximum, so that a sun reflected in a few pixels does not darken
// the rest of the image.
double auto_exposure(const cv::Mat& linear);

// float (CV_32FC1/3) -> binary16 bit patterns, row-major and channel-interleaved (OpenCV's
// conversion: round to nearest even); values beyond 65504 become 65504.
std::vector<uint16_t> to_half(const cv::Mat& linear);

// Byte planes (low bytes, then high), zlib-compressed.
std::string pack_half(const std::vector<uint16_t>& half);
// zlib-compressed bytes, at zlib's fastest level (Z_BEST_SPEED): level 6 made packing the report's
// images most of its time (issue 33), for data scripts ~10 % smaller.
std::string pack_bytes(const std::vector<uint8_t>& bytes);
// The inverse of pack_*: zlib-inflated bytes (tests).
std::vector<uint8_t> unpack(const std::string& packed);

std::string base64(const std::string& bytes);

// An EXR read and packed for the page (DataStore::prepare()).
struct PreparedImage {
    FloatImageInfo info; // without its key (the data script's name, given when it is written)
    std::string meta, packed;
    uint64_t hash = 0;
};

// Writes the data scripts of one report into out_dir/data/, each once.
class DataStore {
  public:
    DataStore(std::filesystem::path results_dir, std::filesystem::path out_dir);
    // An EXR (path relative to the results folder, as in results.json); nullopt when it is
    // missing or unreadable (the page then shows the PNG with its fixed exposure).
    std::optional<FloatImageInfo> image(const std::string& exr_rel);
    // Reads and packs these EXRs on `threads` threads (0: the machine's), for image() to write when the
    // page asks for them: the report's largest cost, which was serial after the tests (issue 33). What
    // the page never asks for is never written.
    void prepare(const std::vector<std::string>& exr_rels, int threads = 0);
    // A sphere id map (8-bit PNG, 0 background, i+1 sphere i) with its spheres ({label, roughness,
    // metallic}, in the script's meta); nullopt when missing.
    std::optional<std::string> id_map(const std::string& png_rel, const nlohmann::json& spheres);
    // A thumbnail of an EXR for the grid of passing tests: at most max_width x max_height, at the
    // image's automatic exposure, through the display transform (thumbs/<key>.png); nullopt when the
    // EXR is missing. The PNG the harness wrote has exposure 0, white wherever the sun lights it.
    std::optional<std::string> thumbnail(const std::string& exr_rel, int max_width, int max_height);
    size_t files() const { return keys_.size(); } // distinct data scripts this report uses

  private:
    std::string write(const std::string& meta_json, const std::string& packed, uint64_t content_hash);
    std::filesystem::path results_dir_, out_dir_;
    std::map<std::string, std::optional<FloatImageInfo>> images_;
    std::map<std::string, std::optional<PreparedImage>> prepared_;
    std::map<std::string, std::optional<std::string>> maps_;
    std::set<std::string> keys_;
};

} // namespace iblcheck::report
