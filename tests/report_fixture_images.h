// Synthetic images for the report's fixtures (report_fixture.cpp, report_ci_fixture.cpp): rows of
// shaded spheres, their id maps and sphere lists, FLIP-like error maps, and the files a run writes
// for them (a PNG through the display transform beside a half-float EXR).
#pragma once
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace iblcheck::testutil::fixture {

// A row of spheres (or two rows), linear RGB: shaded discs, a hot highlight on each when `sun`.
cv::Mat spheres(int w, int h, int rows, float gain, bool sun);
// Sphere ids of spheres(): 0 background, 1 + row * per_row + i (CV_32F, id / 255).
cv::Mat sphere_ids(int w, int h, int rows);
// {label, roughness, metallic} of each sphere of spheres(): metal above, dielectric below.
nlohmann::json sphere_list(int per_row, int rows);
// A FLIP-like error map: relative luminance difference, at most 1.
cv::Mat error_map(const cv::Mat& a, const cv::Mat& b);
// root/rel as a PNG (display transform) and its half-float EXR.
void write_image(const std::filesystem::path& root, const std::string& rel, const cv::Mat& linear);
// root/rel as a magma PNG and its half-float EXR.
void write_error(const std::filesystem::path& root, const std::string& rel, const cv::Mat& err);
// A comparison's images under images/<dir>/: test, <golden>, <golden>_flip and their EXRs.
nlohmann::json images(const std::string& dir, const std::string& golden);

} // namespace iblcheck::testutil::fixture
