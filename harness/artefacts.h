// The image files of one test, under <out>/images/<test>/; results name them relative to <out>.
// Each image a person looks at is written twice: a PNG through the display transform (what SSIM
// measured) and a half-float EXR beside it, the linear data the report's exposure control, colour
// scale and exceedance mask work on.
#pragma once
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "renderers/render_api.h"

namespace iblcheck {

struct Artefacts {
    std::filesystem::path dir;
    std::string rel; // "images/<test>/"

    // The folder of `test` under `out_dir`; none (false) when out_dir is empty: no files.
    static Artefacts for_test(const std::filesystem::path& out_dir, const std::string& test);
    explicit operator bool() const { return !dir.empty(); }

    // "a/b.png" -> "a/b.exr".
    static std::string exr(const std::string& png);
    // Writes `name` (PNG, display transform) and, with_exr, its half-float EXR; returns the PNG's path.
    std::string png(const std::string& name, const cv::Mat& linear, bool with_exr = true) const;
    // A golden many tests compare with (a reference) as one half-float EXR per run under
    // images/_goldens/ (the same pixels are not written again for every test): its path.
    std::string shared_exr(const std::string& golden_rel, const cv::Mat& linear) const;
    // A FLIP error map as a magma PNG and its EXR; returns the PNG's path.
    std::string heatmap(const std::string& name, const cv::Mat& errmap) const;
    // A comparison's images: {test, golden, heatmap} PNGs and their EXRs (test_exr, golden_exr, error_exr).
    static nlohmann::json images(const std::string& test, const std::string& golden, const std::string& heatmap);
    // Which sphere is where (the report names the sphere under the pointer): an 8-bit id map.
    // From the render's coverage; null when it has more spheres than the map holds.
    nlohmann::json layout(const SphereCoverage& coverage) const;
    // The full-precision render, kept beside the results when the test did not pass.
    void keep_float_render(const cv::Mat& image) const;
};

} // namespace iblcheck
