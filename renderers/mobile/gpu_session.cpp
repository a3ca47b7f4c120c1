#include "gpu_session.h"

namespace iblcheck {

GpuSession::GpuSession(const vk::ContextOptions& options) : ctx_(std::make_unique<vk::Context>(options)) {}

const vk::ComputePipeline& GpuSession::pipeline(const std::string& shader, const vk::Defines& defines,
                                                const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                                                const vk::CompileOptions& options) {
    std::string key = shader;
    for (const auto& [k, v] : defines) key += ";" + k + "=" + v;
    if (options.emulate_fp16) key += ";pass:fp16-emulation";
    if (options.count_instructions) key += ";count_instructions";
    auto it = pipelines_.find(key);
    if (it != pipelines_.end()) return *it->second;
    vk::CompiledShader compiled = vk::compile_compute_shader(shader, defines, options);
    if (!options.count_instructions) shader_hashes_[shader] = compiled.source_hash;
    auto p = std::make_unique<vk::ComputePipeline>(*ctx_, compiled, bindings, push_bytes);
    return *pipelines_.emplace(key, std::move(p)).first->second;
}

} // namespace iblcheck
