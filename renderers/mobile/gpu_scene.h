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
// Reads back a vec4 image (rgb + coverage) into CV_32FC3 and returns the mean coverage.
double read_back_image(const vk::Buffer& buf, int width, int height, cv::Mat& rgb);
} // namespace iblcheck
