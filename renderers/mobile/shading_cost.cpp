#include "shading_cost.h"

#include <cstring>

#include "cost_store.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "renderers/vulkan/spirv_cost.h"

namespace iblcheck {

namespace {

// The store's key of a compute pass's count: its inputs (ShadingPass), the counted module's source
// hash and the timed pass's output image.
std::string compute_cost_key(GpuSession& gpu, const ShadingPass& pass, const vk::CompileOptions& counting,
                             const vk::Buffer& out) {
    std::string layout = std::to_string(pass.out_binding);
    for (VkDescriptorType t : pass.binding_types) layout += "," + std::to_string(int(t));
    return cost_store_key(
        gpu, {"compute", pass.inputs_hash, vk::compile_compute_shader(pass.shader, pass.defines, counting).source_hash, layout,
              bytes_hash(pass.push, pass.push_bytes), std::to_string(pass.width) + "x" + std::to_string(pass.height),
              bytes_hash(out.mapped, size_t(out.size))});
}

} // namespace

std::optional<double> shading_instructions_per_pixel(GpuSession& gpu, const ShadingPass& pass, const vk::Buffer& out) {
    ProfileStage stage("counting_twin");
    vk::Context& ctx = gpu.ctx();
    if (!ctx.info().int64_atomics) return std::nullopt;
    vk::CompileOptions options = pass.options;
    options.count_instructions = true;
    const std::string key = pass.inputs_hash.empty() ? std::string() : compute_cost_key(gpu, pass, options, out);
    if (!key.empty())
        if (std::optional<double> stored = load_cost(key)) return stored;
    const vk::ComputePipeline& counted = gpu.pipeline(pass.shader, pass.defines, pass.binding_types, pass.push_bytes, options);
    vk::Buffer scratch = ctx.create_buffer(out.size);
    std::vector<vk::Binding> bindings = pass.bindings;
    for (vk::Binding& b : bindings)
        if (b.binding == pass.out_binding) b.buffer = scratch.buffer;
    uint64_t total = vk::count_dispatch_instructions(ctx, counted, bindings, pass.push, pass.push_bytes,
                                                     uint32_t(pass.width + 7) / 8, uint32_t(pass.height + 7) / 8, 1);
    if (std::memcmp(scratch.mapped, out.mapped, size_t(out.size)) != 0)
        throw Error(pass.shader + ": the instruction-counting twin computed another image than the timed pass; "
                                  "its count would not describe the frame");
    const double per_pixel = double(total) / (double(pass.width) * pass.height);
    if (!key.empty()) save_cost(key, per_pixel);
    return per_pixel;
}

nlohmann::json cost_provenance(std::optional<double> instructions_per_pixel, double texture_fetches_per_pixel) {
    return {{"spirv_instructions_per_pixel", instructions_per_pixel ? nlohmann::json(*instructions_per_pixel) : nlohmann::json()},
            {"texture_fetches_per_pixel", texture_fetches_per_pixel}};
}

} // namespace iblcheck
