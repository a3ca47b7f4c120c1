#include "gpu_scene.h"

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "kernel/errors.h"

namespace iblcheck {

namespace {
// Divides by the length (vec3.h's normalize multiplies by its reciprocal): the camera basis every
// committed golden was rendered with depends on these last bits.
Vec3f normalize_by_division(Vec3f a) {
    float l = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    return {a.x / l, a.y / l, a.z / l};
}
void put(float* p, Vec3f v, float w) {
    p[0] = v.x;
    p[1] = v.y;
    p[2] = v.z;
    p[3] = w;
}
} // namespace

Scene scene_for(const TestSpec& spec, int& width, int& height) {
    Scene scene = build_scene(spec.scene, spec.options);
    width = spec.width > 0 ? spec.width : scene.width;
    height = spec.height > 0 ? spec.height : scene.height;
    return scene;
}

bool scene_uses_ao(const Scene& scene) {
    for (const Sphere& sp : scene.spheres)
        if (sp.material.ao != 1.0f) return true;
    return false;
}

vk::Buffer upload_scene(vk::Context& ctx, const Scene& scene) {
    // A fourth vec4 per sphere (ao_pad) only when a sphere is occluded: scene.glsl declares it under
    // MATERIAL_AO, so scenes without AO keep the layout (and the shaders' code) they had.
    const bool ao = scene_uses_ao(scene);
    if (scene.spheres.size() > kSceneSphereCapacity)
        throw Error(
            fmt::format("scene '{}' has {} spheres; the shaders' scene buffer holds at most {} (renderers/mobile/gpu_scene.h)",
                        scene.name, scene.spheres.size(), kSceneSphereCapacity));
    vk::Buffer buf = ctx.create_buffer(scene_buffer_bytes(ao));
    std::memset(buf.mapped, 0, scene_buffer_bytes(ao));
    auto* f = buf.as<float>();
    const Camera& c = scene.camera;
    // scene.h: forward = normalize(target − eye), right = normalize(forward × world_up), up = right × forward.
    Vec3f fwd = normalize_by_division(c.target - c.eye);
    Vec3f right = normalize_by_division(cross(fwd, c.world_up));
    Vec3f up = cross(right, fwd);
    put(f + 0, c.eye, c.orthographic ? 1.0f : 0.0f);
    put(f + 4, fwd, c.half_height);
    put(f + 8, right, float(std::tan(c.fov_y_deg * 3.14159265358979323846 / 360.0)));
    put(f + 12, up, 0);
    uint32_t count = uint32_t(scene.spheres.size());
    std::memcpy(f + 16, &count, 4);
    float* s = f + 20;
    for (const Sphere& sp : scene.spheres) {
        put(s, sp.center, sp.radius);
        put(s + 4, sp.material.base_color, sp.material.metallic);
        s[8] = sp.material.roughness;
        s[9] = sp.bump_amplitude;
        s[10] = sp.bump_frequency;
        s[11] = sp.bump_phase;
        s += 12;
        if (ao) {
            put(s, {sp.material.ao, 0, 0}, 0);
            s += 4;
        }
    }
    return buf;
}

std::string coverage_problem(const float* rgba, int width, int height, int ssaa, const std::string& shader) {
    size_t count = 0;
    int first_x = -1, first_y = -1;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            if (!std::isfinite(rgba[4 * (size_t(y) * width + x) + 3]) && count++ == 0) first_x = x / ssaa, first_y = y / ssaa;
    if (!count) return {};
    return fmt::format("{}: alpha (coverage) channel: {} non-finite value(s) (NaN/Inf), first at x={}, y={}", shader, count,
                       first_x, first_y);
}

double read_back_image(const vk::Buffer& buf, int width, int height, cv::Mat& rgb, const std::string& shader,
                       std::string& problem) {
    rgb.create(height, width, CV_32FC3);
    const float* src = static_cast<const float*>(buf.mapped);
    problem = coverage_problem(src, width, height, 1, shader);
    double coverage = 0;
    for (int y = 0; y < height; ++y) {
        float* row = rgb.ptr<float>(y);
        for (int x = 0; x < width; ++x) {
            const float* p = src + 4 * (size_t(y) * width + x);
            row[3 * x] = p[0];
            row[3 * x + 1] = p[1];
            row[3 * x + 2] = p[2];
            coverage += p[3];
        }
    }
    return coverage / (double(width) * height);
}

} // namespace iblcheck
