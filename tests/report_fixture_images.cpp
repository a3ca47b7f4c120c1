// Synthetic images for the report's fixtures (report_fixture_images.h).
#include "tests/report_fixture_images.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "image_io/image_io.h"
#include "metrics/display_transform.h"
#include "metrics/flip.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck::testutil::fixture {

// A row of spheres (or two rows), linear RGB: shaded discs, a hot highlight on each when `sun`.
cv::Mat spheres(int w, int h, int rows, float gain, bool sun) {
    cv::Mat m(h, w, CV_32FC3, cv::Scalar(0.05f, 0.05f, 0.06f));
    const int per_row = w / 48, r = std::min(20, h / (2 * rows) - 2);
    for (int row = 0; row < rows; ++row)
        for (int i = 0; i < per_row; ++i) {
            const int cx = 24 + 48 * i, cy = h / (2 * rows) + row * h / rows;
            for (int y = cy - r; y <= cy + r; ++y)
                for (int x = cx - r; x <= cx + r; ++x) {
                    const double d2 = double((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (r * r);
                    if (d2 > 1 || x < 0 || y < 0 || x >= w || y >= h) continue;
                    const float s = float(std::sqrt(1 - d2)) * gain;
                    cv::Vec3f c = row == 0 ? cv::Vec3f(0.9f, 0.6f + 0.02f * i, 0.4f) : cv::Vec3f(0.7f, 0.7f, 0.7f);
                    c *= s * (0.6f + 0.15f * float(i));
                    const double hx = x - (cx - r / 3), hy = y - (cy - r / 3);
                    if (sun && hx * hx + hy * hy < 4) c += cv::Vec3f(2500.0f, 2300.0f, 2100.0f);
                    m.at<cv::Vec3f>(y, x) = c;
                }
        }
    return m;
}

// Sphere ids of spheres(): 0 background, 1 + row * per_row + i.
cv::Mat sphere_ids(int w, int h, int rows) {
    cv::Mat ids(h, w, CV_32F, cv::Scalar(0));
    const int per_row = w / 48, r = std::min(20, h / (2 * rows) - 2);
    for (int row = 0; row < rows; ++row)
        for (int i = 0; i < per_row; ++i) {
            const int cx = 24 + 48 * i, cy = h / (2 * rows) + row * h / rows;
            for (int y = std::max(0, cy - r); y <= std::min(h - 1, cy + r); ++y)
                for (int x = std::max(0, cx - r); x <= std::min(w - 1, cx + r); ++x)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r)
                        ids.at<float>(y, x) = float(1 + row * per_row + i) / 255.0f;
        }
    return ids;
}

json sphere_list(int per_row, int rows) {
    json a = json::array();
    for (int row = 0; row < rows; ++row)
        for (int i = 0; i < per_row; ++i) {
            const double rough = per_row > 1 ? double(i) / (per_row - 1) : 0.5;
            a.push_back({{"label", fmt::format("{} r={}", row == 0 ? "metal" : "dielectric", std::round(rough * 10) / 10)},
                         {"roughness", rough},
                         {"metallic", row == 0 ? 1.0 : 0.0}});
        }
    return a;
}

// A FLIP-like error map: relative luminance difference, at most 1.
cv::Mat error_map(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat e(a.size(), CV_32F);
    for (int y = 0; y < a.rows; ++y)
        for (int x = 0; x < a.cols; ++x) {
            const cv::Vec3f p = a.at<cv::Vec3f>(y, x), q = b.at<cv::Vec3f>(y, x);
            const float la = p[0] + p[1] + p[2], lb = q[0] + q[1] + q[2];
            e.at<float>(y, x) = std::min(1.0f, 2.0f * std::fabs(la - lb) / (la + lb + 1e-3f));
        }
    return e;
}

void write_image(const fs::path& root, const std::string& rel, const cv::Mat& linear) {
    fs::create_directories((root / rel).parent_path());
    write_png((root / rel).string(), display_transform(linear));
    write_exr_half((root / (rel.substr(0, rel.rfind('.')) + ".exr")).string(), linear);
}
void write_error(const fs::path& root, const std::string& rel, const cv::Mat& err) {
    fs::create_directories((root / rel).parent_path());
    write_png((root / rel).string(), magma_heatmap(err));
    write_exr_half((root / (rel.substr(0, rel.rfind('.')) + ".exr")).string(), err);
}
namespace {
std::string exr(const std::string& png) { return png.substr(0, png.rfind('.')) + ".exr"; }
} // namespace

json images(const std::string& dir, const std::string& golden) {
    const std::string t = "images/" + dir + "/test.png", g = "images/" + dir + "/" + golden + ".png",
                      h = "images/" + dir + "/" + golden + "_flip.png";
    return {{"test", t}, {"golden", g}, {"heatmap", h}, {"test_exr", exr(t)}, {"golden_exr", exr(g)}, {"error_exr", exr(h)}};
}

} // namespace iblcheck::testutil::fixture
