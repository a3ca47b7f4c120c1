// What a process keeps between renders on the GPU: the Vulkan context and the compute and graphics
// pipelines, cached by shader name + defines (creating a pipeline makes lavapipe compile LLVM,
// ~0.1 s each).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "renderers/vulkan/context.h"
#include "renderers/vulkan/graphics_pipeline.h"

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
    // The graphics pipeline of `vertex` + `fragment` (both compiled with `defines` and `options`)
    // drawing into targets of `target`'s format.
    const vk::GraphicsPipeline& graphics_pipeline(const std::string& vertex, const std::string& fragment,
                                                  const vk::Defines& defines, const std::vector<VkDescriptorType>& bindings,
                                                  uint32_t push_bytes, const vk::TargetFormat& target,
                                                  const vk::CompileOptions& options = {});
    // A per-session cache of anything built on the device (the precompute passes' results, keyed by
    // environment hash + settings): an animated sequence re-renders the same environment per frame.
    // It keeps the kCachedEntries most recently used: the runner gives a worker the tests that share a
    // precompute one after another, and a nightly kept all 133 of its precomputes (a 512 cube, a
    // 4096-sample prefilter...) to its end, 1.1-1.2 GB at its peak (issue 33).
    static constexpr size_t kCachedEntries = 4;
    template <class T> std::shared_ptr<T> cached(const std::string& key) {
        auto it = cache_.find(key);
        if (it == cache_.end()) return nullptr;
        it->second.last_use = ++uses_;
        return std::static_pointer_cast<T>(it->second.value);
    }
    void store(const std::string& key, std::shared_ptr<void> value);

    // Hash of the sources each pipeline was compiled from, for provenance.
    const std::map<std::string, std::string>& shader_hashes() const { return shader_hashes_; }

  private:
    std::unique_ptr<vk::Context> ctx_;
    std::map<std::string, std::unique_ptr<vk::ComputePipeline>> pipelines_;
    std::map<std::string, std::unique_ptr<vk::GraphicsPipeline>> graphics_pipelines_;
    std::map<std::string, std::string> shader_hashes_;
    struct CacheEntry {
        std::shared_ptr<void> value;
        uint64_t last_use = 0;
    };
    std::map<std::string, CacheEntry> cache_;
    uint64_t uses_ = 0;
};

} // namespace iblcheck
