// Graphics pipelines drawing into an offscreen multisampled target, nothing IBL-specific: the
// counterpart of ComputePipeline (context.h) for work a device runs in its raster pipeline
// (vertex + fragment stages, MSAA, depth test, resolve). Same descriptor model: set 0 with push
// descriptors, bound to both stages, and one push-constant range both stages see.
#pragma once
#include <array>

#include "context.h"

namespace iblcheck::vk {

// What a target holds and a pipeline draws into: colour (resolved to one sample at the end of the
// pass) and depth, both with `samples` samples.
struct TargetFormat {
    VkFormat color = VK_FORMAT_R32G32B32A32_SFLOAT;
    VkFormat depth = VK_FORMAT_D32_SFLOAT;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_4_BIT;
};

// EnvironmentError naming the device and the missing capability unless it can render `format`
// (a graphics queue, the sample count for colour and depth, standard sample locations when
// multisampled: shaders may rely on them).
void require_target_support(const Context& ctx, const TargetFormat& format);

// An offscreen target: a multisampled colour and depth attachment, a single-sample resolve image,
// and the render pass that clears them, draws, and resolves colour by averaging its samples
// (Vulkan resolves float formats by averaging).
class OffscreenTarget {
  public:
    OffscreenTarget(Context& ctx, uint32_t width, uint32_t height, const TargetFormat& format);
    ~OffscreenTarget();
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;

    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    // Begins the render pass: colour cleared to `clear`, depth to 1; viewport and scissor cover the target.
    void begin(VkCommandBuffer cmd, const std::array<float, 4>& clear) const;
    // Ends it: the resolve image then holds the average of each pixel's samples.
    void end(VkCommandBuffer cmd) const;
    // After end(): copies the resolved colour, rows tightly packed, into `dst` (a host-visible
    // buffer of width·height·texel bytes) and makes it visible to the host.
    void copy_resolved(VkCommandBuffer cmd, const Buffer& dst) const;

  private:
    struct Attachment {
        VkImage image = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkImageView view = VK_NULL_HANDLE;
    };
    Attachment make_attachment(VkFormat format, VkSampleCountFlagBits samples, VkImageUsageFlags usage,
                               VkImageAspectFlags aspect);
    void destroy(Attachment& a);
    void release(); // everything created so far (the destructor, and a constructor that throws)

    Context& ctx_;
    uint32_t width_, height_;
    TargetFormat format_;
    Attachment color_, depth_, resolve_;
    VkRenderPass render_pass_ = VK_NULL_HANDLE;
    VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
};

struct GraphicsPipelineDesc {
    const CompiledShader* vertex = nullptr;
    const CompiledShader* fragment = nullptr;
    std::vector<VkDescriptorType> bindings; // binding i's type; visible to both stages
    uint32_t push_constant_bytes = 0;       // one range, both stages
    TargetFormat target;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
    bool depth_test = true; // less, with writes
};

class GraphicsPipeline {
  public:
    // A stage compiled with count_instructions (spirv_cost.h) makes the layout bind the counter
    // at kCostBinding too; the device then needs vertexPipelineStoresAndAtomics and
    // fragmentStoresAndAtomics (DeviceInfo::graphics_stores).
    GraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc);
    ~GraphicsPipeline();
    GraphicsPipeline(const GraphicsPipeline&) = delete;
    GraphicsPipeline& operator=(const GraphicsPipeline&) = delete;

    bool counts_instructions() const { return counts_; }
    // Inside an OffscreenTarget's pass of the same TargetFormat: bind + push descriptors + push
    // constants + a non-indexed draw without vertex buffers (the vertex shader makes its vertices).
    void draw(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push, uint32_t push_bytes,
              uint32_t vertex_count, uint32_t instance_count) const;

  private:
    void release();
    Context& ctx_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkRenderPass render_pass_ = VK_NULL_HANDLE; // compatible with every OffscreenTarget of the format
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    bool counts_ = false;
};

} // namespace iblcheck::vk
