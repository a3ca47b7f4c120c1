#include "renderers/scenes/coverage.h"

namespace iblcheck {

namespace {
// Pixel -> sphere index (-1 for background), from the same camera and intersection the renderers use.
int sphere_index(const Scene& scene, int width, int height, int x, int y) {
    Vec3f o, d;
    camera_ray(scene, width, height, x + 0.5, y + 0.5, o, d);
    Hit h = intersect(scene, o, d);
    return h.hit ? h.sphere : -1;
}

std::string sphere_label(const Scene& scene, size_t i) {
    return i < scene.labels.size() ? scene.labels[i] : "sphere " + std::to_string(i);
}
} // namespace

SphereCoverage sphere_coverage(const Scene& scene, int width, int height) {
    SphereCoverage out;
    out.ids = cv::Mat(height, width, CV_32S);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) out.ids.at<int>(y, x) = sphere_index(scene, width, height, x, y);
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        out.spheres.push_back({sphere_label(scene, i), scene.spheres[i].material.roughness, scene.spheres[i].material.metallic});
    return out;
}

} // namespace iblcheck
