#include "image_compare.h"

#include <cmath>

#include "metrics/display_transform.h"
#include "metrics/flip_json.h"
#include "metrics/psnr.h"
#include "metrics/ssim.h"
#include "renderers/scenes/scene.h"

using nlohmann::json;

namespace iblcheck {

json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out) {
    FlipOptions fo;
    fo.threads = flip_threads;
    FlipResult f = compute_flip_hdr(golden, test, fo);
    PsnrResult p = compute_psnr(display_transform(golden), display_transform(test));
    json j;
    j["flip"] = flip_json(f);
    if (ssim_applicable(golden))
        j["ssim"] = {{"mean", compute_ssim_hdr(golden, test).mean}};
    else
        j["ssim"] = {{"mean", nullptr}, {"not_applicable", "smaller than SSIM's 11x11 window"}};
    // Identical images have PSNR +inf, which JSON cannot hold: 999 stands for it.
    j["psnr"] = {{"db", std::isfinite(p.db) ? json(p.db) : json(999.0)}, {"rmse", p.rmse}, {"max_abs", p.max_abs}};
    if (flip_out) *flip_out = std::move(f);
    return j;
}

namespace {
// Pixel -> sphere index (-1 for background), from the same camera and intersection the renderers use.
int sphere_index(const Scene& scene, int width, int height, int x, int y) {
    Vec3f o, d;
    camera_ray(scene, width, height, x + 0.5, y + 0.5, o, d);
    Hit h = intersect(scene, o, d);
    return h.hit ? h.sphere : -1;
}

std::string sphere_label(const Scene& scene, int i) {
    return size_t(i) < scene.labels.size() ? scene.labels[size_t(i)] : "sphere " + std::to_string(i);
}
} // namespace

json per_sphere_errors(const TestSpec& spec, const cv::Mat& errmap) {
    Scene scene = build_scene(spec.scene, spec.options);
    if (scene.spheres.size() < 2) return json();
    std::vector<double> sum(scene.spheres.size(), 0.0);
    std::vector<long> count(scene.spheres.size(), 0);
    for (int y = 0; y < errmap.rows; ++y)
        for (int x = 0; x < errmap.cols; ++x) {
            int id = sphere_index(scene, errmap.cols, errmap.rows, x, y);
            if (id < 0) continue;
            sum[size_t(id)] += errmap.at<float>(y, x);
            count[size_t(id)]++;
        }
    json out = json::array();
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        if (!count[i]) continue;
        out.push_back({{"label", sphere_label(scene, int(i))},
                       {"roughness", scene.spheres[i].material.roughness},
                       {"metallic", scene.spheres[i].material.metallic},
                       {"flip_mean", sum[i] / double(count[i])}});
    }
    return out;
}

SphereLayout sphere_layout(const TestSpec& spec, int width, int height) {
    Scene scene = build_scene(spec.scene, spec.options);
    SphereLayout out;
    if (scene.spheres.size() > 254) return out; // does not fit the 8-bit map: no layout
    out.ids = cv::Mat(height, width, CV_8U);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) out.ids.at<uchar>(y, x) = uchar(sphere_index(scene, width, height, x, y) + 1);
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        out.spheres.push_back({{"label", sphere_label(scene, int(i))},
                               {"roughness", scene.spheres[i].material.roughness},
                               {"metallic", scene.spheres[i].material.metallic}});
    return out;
}

std::string sphere_at(const TestSpec& spec, int width, int height, int x, int y) {
    Scene scene = build_scene(spec.scene, spec.options);
    int id = sphere_index(scene, width, height, x, y);
    return id < 0 ? "" : sphere_label(scene, id);
}

} // namespace iblcheck
