// The deterministic cost of a shading pass (issue 14): SPIR-V instructions executed per pixel,
// measured by an untimed extra dispatch of the pass's instrumented twin
// (renderers/vulkan/spirv_cost.h). The timed dispatch stays un-instrumented, so frame timings
// keep their meaning.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gpu_session.h"

namespace iblcheck {

// A shading pass as the timed dispatch ran it.
struct ShadingPass {
    std::string shader; // "shade_spheres.comp"
    vk::Defines defines;
    std::vector<VkDescriptorType> binding_types;
    vk::CompileOptions options; // as the timed pipeline was compiled (fp16 emulation)
    std::vector<vk::Binding> bindings;
    uint32_t out_binding = 5; // the vec4 image the pass writes
    const void* push = nullptr;
    uint32_t push_bytes = 0;
    int width = 0, height = 0; // image size; the dispatch is 8x8 workgroups over it
    // shading_inputs_hash() of what the bindings hold besides the output: the count is stored under
    // it (cost_store.h) and read in a later run; empty: counted every time.
    std::string inputs_hash;
};

// Dynamic SPIR-V instructions of the whole dispatch (every invocation, every ssaa ray) per image
// pixel. The instrumented twin writes a scratch image, which must equal `out` (what the timed pass
// wrote) bit for bit: otherwise the count would describe another computation and this throws
// Error. nullopt when the device cannot count (no shaderInt64 + shaderBufferInt64Atomics). A count
// stored for the same inputs (cost_store.h) is returned without the twin.
std::optional<double> shading_instructions_per_pixel(GpuSession& gpu, const ShadingPass& pass, const vk::Buffer& out);

// The render's provenance entry "cost": {"spirv_instructions_per_pixel": X or null,
// "texture_fetches_per_pixel": Y}.
nlohmann::json cost_provenance(std::optional<double> instructions_per_pixel, double texture_fetches_per_pixel);

} // namespace iblcheck
