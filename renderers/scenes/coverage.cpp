#include "renderers/scenes/coverage.h"

#include <map>
#include <mutex>
#include <string>

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

// What the pixel -> sphere map depends on: the size, the camera and each sphere's centre and radius
// (intersect() reads nothing else), as bytes.
std::string geometry_key(const Scene& scene, int width, int height) {
    std::string key;
    auto add = [&key](const auto& v) { key.append(reinterpret_cast<const char*>(&v), sizeof v); };
    add(width), add(height);
    const Camera& c = scene.camera;
    add(c.orthographic), add(c.eye), add(c.target), add(c.world_up), add(c.half_height), add(c.fov_y_deg);
    for (const Sphere& s : scene.spheres) add(s.center), add(s.radius);
    return key;
}

// The map, traced once per geometry and size in a process (issue 33: the ci suite traced the same
// 528x96 roughness sweep 45 times, ~6 % of its CPU time).
cv::Mat sphere_ids(const Scene& scene, int width, int height) {
    static std::mutex mutex;
    static std::map<std::string, cv::Mat> traced;
    const std::string key = geometry_key(scene, width, height);
    {
        std::lock_guard lock(mutex);
        if (auto it = traced.find(key); it != traced.end()) return it->second.clone();
    }
    cv::Mat ids(height, width, CV_32S);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) ids.at<int>(y, x) = sphere_index(scene, width, height, x, y);
    std::lock_guard lock(mutex);
    if (traced.size() >= 64) traced.clear(); // a bound for long sweeps of sizes and scenes
    traced.emplace(key, ids);
    return ids.clone();
}
} // namespace

SphereCoverage sphere_coverage(const Scene& scene, int width, int height) {
    SphereCoverage out;
    out.ids = sphere_ids(scene, width, height);
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        out.spheres.push_back({sphere_label(scene, i), scene.spheres[i].material.roughness, scene.spheres[i].material.metallic});
    return out;
}

} // namespace iblcheck
