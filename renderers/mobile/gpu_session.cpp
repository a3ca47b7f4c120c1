#include "gpu_session.h"

#include "kernel/profile.h"

namespace iblcheck {

namespace {
std::string pipeline_key(const std::string& shaders, const vk::Defines& defines, const vk::CompileOptions& options) {
    std::string key = shaders;
    for (const auto& [k, v] : defines) key += ";" + k + "=" + v;
    if (options.emulate_fp16) key += ";pass:fp16-emulation";
    if (options.count_instructions) key += ";count_instructions";
    if (!options.ibl_shade.empty()) key += ";ibl_shade=" + options.ibl_shade.string();
    return key;
}
} // namespace

GpuSession::GpuSession(const vk::ContextOptions& options) : ctx_(std::make_unique<vk::Context>(options)) {}

const vk::ComputePipeline& GpuSession::pipeline(const std::string& shader, const vk::Defines& defines,
                                                const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                                                const vk::CompileOptions& options) {
    std::string key = pipeline_key(shader, defines, options);
    auto it = pipelines_.find(key);
    if (it != pipelines_.end()) return *it->second;
    vk::CompiledShader compiled = vk::compile_compute_shader(shader, defines, options);
    if (!options.count_instructions) shader_hashes_[shader] = compiled.source_hash;
    ProfileStage stage("pipeline_create"); // lavapipe compiles the module with LLVM
    auto p = std::make_unique<vk::ComputePipeline>(*ctx_, compiled, bindings, push_bytes);
    return *pipelines_.emplace(key, std::move(p)).first->second;
}

const vk::GraphicsPipeline& GpuSession::graphics_pipeline(const std::string& vertex, const std::string& fragment,
                                                          const vk::Defines& defines,
                                                          const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                                                          const vk::TargetFormat& target, const vk::CompileOptions& options) {
    std::string key = pipeline_key(vertex + "+" + fragment, defines, options) + ";target=" + std::to_string(int(target.color)) +
                      "/" + std::to_string(int(target.depth)) + "/" + std::to_string(int(target.samples));
    auto it = graphics_pipelines_.find(key);
    if (it != graphics_pipelines_.end()) return *it->second;
    vk::CompiledShader vs = vk::compile_shader(vertex, defines, options);
    vk::CompiledShader fs = vk::compile_shader(fragment, defines, options);
    if (!options.count_instructions) {
        shader_hashes_[vertex] = vs.source_hash;
        shader_hashes_[fragment] = fs.source_hash;
    }
    vk::GraphicsPipelineDesc desc;
    desc.vertex = &vs;
    desc.fragment = &fs;
    desc.bindings = bindings;
    desc.push_constant_bytes = push_bytes;
    desc.target = target;
    ProfileStage stage("pipeline_create");
    auto p = std::make_unique<vk::GraphicsPipeline>(*ctx_, desc);
    return *graphics_pipelines_.emplace(key, std::move(p)).first->second;
}

void GpuSession::store(const std::string& key, std::shared_ptr<void> value) {
    cache_[key] = {std::move(value), ++uses_};
    while (cache_.size() > kCachedEntries) {
        auto oldest = cache_.begin();
        for (auto it = cache_.begin(); it != cache_.end(); ++it)
            if (it->second.last_use < oldest->second.last_use) oldest = it;
        cache_.erase(oldest); // a render still holding it keeps it alive (shared_ptr)
    }
}

} // namespace iblcheck
