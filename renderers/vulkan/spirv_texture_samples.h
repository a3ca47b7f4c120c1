// Texture samples of a team's shading function, read from its SPIR-V (docs/SHADER_CONTRACT.md):
// the texture-fetch half of the cost gate for a shader the host cannot know the lookups of. The
// built-in shading's fetches are counted from its options (renderers/mobile/mobile_renderer.cpp).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace iblcheck::vk {

// The image-sample instructions (OpImageSample*, OpImageFetch, OpImageGather, OpImageDrefGather)
// one call of the function whose debug name starts with `function_prefix` (glslang names
// "ibl_shade(struct-IblSurface-...") executes, each call site of a callee counted once more:
// a static figure, deterministic on every device, that grows when a shader adds a lookup. A
// lookup inside a loop counts once, one in a branch counts as taken. Throws Error when the module
// has no such function or a call cycle (GLSL has no recursion).
double image_samples_per_call(const std::vector<uint32_t>& spirv, const std::string& function_prefix);

} // namespace iblcheck::vk
