// The scene as the shaders read it (scene.glsl's SceneBuffer, std430).
#pragma once
#include <opencv2/core.hpp>

#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"
#include "renderers/vulkan/context.h"

namespace iblcheck {
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
