// The scene as the shaders read it (scene.glsl's SceneBuffer, a std140 uniform block).
#pragma once
#include <cstddef>

#include <opencv2/core.hpp>

#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"
#include "renderers/vulkan/context.h"

namespace iblcheck {
// Why a uniform buffer and not a storage buffer: llvmpipe (Mesa 22.3, lp_bld_nir_soa.c) loads a
// storage buffer one SIMD lane at a time, through the stack, and a uniform buffer at a uniform
// offset once per vector. Every ray reads every sphere (scene.glsl's intersect_scene); through a
// storage buffer the ci suite's shading dispatches took 12.8 s instead of 3.2 s (issue 33).
// A uniform block has a fixed size: kSceneSphereCapacity spheres, the most that Vulkan's minimum
// maxUniformBufferRange holds with the AO member, so the buffer binds on every conforming device.
// scene.glsl's SCENE_SPHERE_CAPACITY is the same count (tests/test_shading_buffers.cpp).
inline constexpr size_t kSceneHeaderBytes = 5 * 16;        // camera (4 vec4) + counts (uvec4)
inline constexpr size_t kSphereBytes = 3 * 16;             // SphereGpu without AO
inline constexpr size_t kSphereBytesWithAo = 4 * 16;       // with ao_pad
inline constexpr size_t kMinMaxUniformBufferRange = 16384; // Vulkan's required limit (spec, "Limits")
constexpr size_t scene_sphere_capacity(size_t uniform_range) { return (uniform_range - kSceneHeaderBytes) / kSphereBytesWithAo; }
inline constexpr size_t kSceneSphereCapacity = scene_sphere_capacity(kMinMaxUniformBufferRange); // 254
// The whole uniform block, as the shader declares it (kSceneSphereCapacity spheres).
constexpr size_t scene_buffer_bytes(bool ao) {
    return kSceneHeaderBytes + (ao ? kSphereBytesWithAo : kSphereBytes) * kSceneSphereCapacity;
}
static_assert(scene_buffer_bytes(true) <= kMinMaxUniformBufferRange);

// The scene's camera and spheres, the unused spheres zero (the buffer's bytes key the stored
// instruction counts). Throws Error for a scene of more than kSceneSphereCapacity spheres.
vk::Buffer upload_scene(vk::Context& ctx, const Scene& scene);
// Whether a sphere has material AO (ao < 1): then each sphere carries a fourth vec4 and the
// shaders that read the scene are compiled with MATERIAL_AO (scene.glsl).
bool scene_uses_ao(const Scene& scene);
// The spec's scene and image size (0 in the spec: the scene's default size).
Scene scene_for(const TestSpec& spec, int& width, int& height);
// Reads back a vec4 image (rgb + coverage) that `shader` wrote into CV_32FC3 and returns the mean
// coverage; `problem` gets coverage_problem()'s message when the alpha channel is not finite.
double read_back_image(const vk::Buffer& buf, int width, int height, cv::Mat& rgb, const std::string& shader,
                       std::string& problem);
// Alpha is coverage (the fraction of a pixel's rays or samples that hit a sphere), and it sizes
// the texture-fetch cost: a NaN/Inf there is the shader's fault, not a change of cost. Returns
// "<shader>: alpha (coverage) channel: N non-finite value(s) (NaN/Inf), first at x=X, y=Y" (image
// pixels: `rgba` is `ssaa` x `ssaa` samples per pixel), or "" when every value is finite
// (RenderResult::non_finite_coverage).
std::string coverage_problem(const float* rgba, int width, int height, int ssaa, const std::string& shader);
} // namespace iblcheck
