// Helpers the GPU pipeline tests share (test_mobile_pipeline, test_mobile_storage_layout,
// test_fragment_shading, test_mobile_cost_fp16): a mobile spec and its render, one lavapipe session
// per test program with validation on, its validation check, and which sphere (and normal) lies under each pixel centre.
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "renderers/environments/environment.h"
#include "renderers/mobile/mobile_renderer.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::testutil {

// A mobile-method test spec: scene, environment and option key=value pairs.
inline TestSpec spec(const std::string& scene, const std::string& env,
                     const std::vector<std::pair<std::string, std::string>>& opts = {}) {
    TestSpec s;
    s.scene = scene;
    s.env = env;
    s.method = "mobile";
    for (auto& [k, v] : opts) s.options.set(k, v);
    return s;
}

// One GPU session per test program, with the Vulkan validation layer when it is installed.
inline GpuSession& session() {
    static GpuSession s(vk::ContextOptions{"", true});
    return s;
}

// The spec validated, then rendered by the mobile method in that session.
inline RenderResult render(const TestSpec& s) {
    validate_spec(s);
    Environment env = load_environment(s.env);
    return render_mobile(session(), env, s);
}

inline void expect_no_validation_errors() {
    auto& ctx = session().ctx();
    EXPECT_EQ(ctx.validation_errors(), 0) << (ctx.validation_messages().empty() ? "" : ctx.validation_messages()[0]);
}

// Sphere index under each pixel centre (−1: background), whether the pixel's 3×3 neighbourhood is
// that same sphere (an interior pixel: no silhouette mixing), and the normal there.
struct PixelInfo {
    int sphere = -1;
    bool interior = false;
    Vec3f normal;
};
inline std::vector<PixelInfo> pixel_info(const TestSpec& s, int w, int h) {
    Scene scene = build_scene(s.scene, s.options);
    std::vector<PixelInfo> info(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Vec3f o, d;
            camera_ray(scene, w, h, x + 0.5, y + 0.5, o, d);
            Hit hit = intersect(scene, o, d);
            info[size_t(y) * w + x] = {hit.hit ? hit.sphere : -1, false, hit.normal};
        }
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            int id = info[size_t(y) * w + x].sphere;
            bool same = id >= 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) same &= info[size_t(y + dy) * w + x + dx].sphere == id;
            info[size_t(y) * w + x].interior = same;
        }
    return info;
}

} // namespace iblcheck::testutil
