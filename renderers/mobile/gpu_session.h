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

    // The pipeline for `shader` compiled with `defines` and `options` (the fp16 emulation pass; the
    // instruction-count instrumentation of renderers/vulkan/spirv_cost.h, for an untimed dispatch that
    // measures the pass's cost), binding types in binding order.
    const vk::ComputePipeline& pipeline(const std::string& shader, const vk::Defines& defines,
                                        const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                                        const vk::CompileOptions& options = {});
    // A per-session cache of anything built on the device (the precompute passes' results, keyed by
    // environment hash + settings): an animated sequence re-renders the same environment per frame.
    template <class T> std::shared_ptr<T> cached(const std::string& key) {
        auto it = cache_.find(key);
        return it == cache_.end() ? nullptr : std::static_pointer_cast<T>(it->second);
    }
    void store(const std::string& key, std::shared_ptr<void> value) { cache_[key] = std::move(value); }

    // Hash of the sources each pipeline was compiled from, for provenance.
    const std::map<std::string, std::string>& shader_hashes() const { return shader_hashes_; }

  private:
    std::unique_ptr<vk::Context> ctx_;
    std::map<std::string, std::unique_ptr<vk::ComputePipeline>> pipelines_;
    std::map<std::string, std::string> shader_hashes_;
    std::map<std::string, std::shared_ptr<void>> cache_;
};

} // namespace iblcheck
