// What a process keeps between renders on the GPU: the Vulkan context and the compute pipelines,
// cached by shader name + defines (creating a pipeline makes lavapipe compile LLVM, ~0.1 s each).
#pragma once
#include <map>
#include <memory>
#include <string>

#include "renderers/vulkan/context.h"

namespace iblcheck {

class GpuSession {
  public:
    explicit GpuSession(const vk::ContextOptions& options = {});
    vk::Context& ctx() { return *ctx_; }

    // The pipeline for `shader` compiled with `defines`, binding types in binding order.
    const vk::ComputePipeline& pipeline(const std::string& shader, const vk::Defines& defines,
                                        const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes);
    // Hash of the sources each pipeline was compiled from, for provenance.
    const std::map<std::string, std::string>& shader_hashes() const { return shader_hashes_; }

  private:
    std::unique_ptr<vk::Context> ctx_;
    std::map<std::string, std::unique_ptr<vk::ComputePipeline>> pipelines_;
    std::map<std::string, std::string> shader_hashes_;
};

} // namespace iblcheck
