#include "graphics_pipeline.h"

#include <string>

#include "kernel/errors.h"
#include "pipeline_layout.h"
#include "spirv_cost.h"
#include "vk_struct.h"

namespace iblcheck::vk {

namespace {

constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Attachment 0: multisampled colour, 1: multisampled depth, 2: single-sample resolve of colour.
// With one sample there is nothing to resolve: colour is attachment 0 alone, depth 1.
VkRenderPass create_render_pass(VkDevice dev, const TargetFormat& f) {
    const bool msaa = f.samples != VK_SAMPLE_COUNT_1_BIT;
    VkAttachmentDescription att[3] = {};
    att[0].format = f.color;
    att[0].samples = f.samples;
    att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att[0].storeOp = msaa ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
    att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att[0].finalLayout = msaa ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    att[1] = att[0];
    att[1].format = f.depth;
    att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    att[2] = att[0];
    att[2].samples = VK_SAMPLE_COUNT_1_BIT;
    att[2].loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[2].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    att[2].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkAttachmentReference resolve_ref{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &color_ref;
    sub.pResolveAttachments = msaa ? &resolve_ref : nullptr;
    sub.pDepthStencilAttachment = &depth_ref;
    // Earlier work (compute passes writing what the shaders read) before the draw; the draw's
    // colour (and the resolve, which happens as a colour write) before the copy that follows.
    VkSubpassDependency deps[2] = {};
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    deps[0].srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    deps[0].dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
                           VK_PIPELINE_STAGE_VERTEX_SHADER_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT;
    deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
    auto ci = vk_struct<VkRenderPassCreateInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO);
    ci.attachmentCount = msaa ? 3 : 2;
    ci.pAttachments = att;
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    ci.dependencyCount = 2;
    ci.pDependencies = deps;
    VkRenderPass rp = VK_NULL_HANDLE;
    check(vkCreateRenderPass(dev, &ci, nullptr, &rp), "vkCreateRenderPass");
    return rp;
}

uint32_t texel_bytes(VkFormat f) {
    switch (f) {
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    case VK_FORMAT_R16G16B16A16_SFLOAT: return 8;
    case VK_FORMAT_R8G8B8A8_UNORM: return 4;
    default: throw Error("OffscreenTarget: copy of this colour format is not implemented");
    }
}

// The vertex and fragment shader modules, destroyed with this object.
class StageModules {
  public:
    explicit StageModules(VkDevice dev) : dev_(dev) {}
    ~StageModules() {
        for (VkShaderModule m : modules_)
            if (m) vkDestroyShaderModule(dev_, m, nullptr);
    }
    StageModules(const StageModules&) = delete;
    StageModules& operator=(const StageModules&) = delete;

    // The module of `stage` (vertex or fragment) made from `shader`, as a pipeline stage.
    VkPipelineShaderStageCreateInfo create(VkShaderStageFlagBits stage, const CompiledShader& shader) {
        VkShaderModule& module = modules_[stage == VK_SHADER_STAGE_VERTEX_BIT ? 0 : 1];
        auto smi = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
        smi.codeSize = shader.spirv.size() * 4;
        smi.pCode = shader.spirv.data();
        check(vkCreateShaderModule(dev_, &smi, nullptr, &module), "vkCreateShaderModule");
        auto info = vk_struct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
        info.stage = stage;
        info.module = module;
        info.pName = "main";
        return info;
    }

  private:
    VkDevice dev_;
    VkShaderModule modules_[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
};

// The fixed-function state of every pipeline here: no vertex buffers, no culling, MSAA without
// sample shading, an optional depth test (less, with writes), no blending, dynamic viewport and
// scissor. It points into itself, hence neither copied nor moved.
struct FixedFunctionState {
    explicit FixedFunctionState(const GraphicsPipelineDesc& d) {
        ia.topology = d.topology;
        vp.viewportCount = 1;
        vp.scissorCount = 1;
        rs.polygonMode = VK_POLYGON_MODE_FILL;
        rs.cullMode = VK_CULL_MODE_NONE;
        rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
        rs.lineWidth = 1.0f;
        ms.rasterizationSamples = d.target.samples;
        ms.sampleShadingEnable = VK_FALSE; // MSAA: one shading per pixel, coverage per sample
        ds.depthTestEnable = d.depth_test;
        ds.depthWriteEnable = d.depth_test;
        ds.depthCompareOp = VK_COMPARE_OP_LESS;
        blend.colorWriteMask =
            VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
        cb.attachmentCount = 1;
        cb.pAttachments = &blend;
        dy.dynamicStateCount = 2;
        dy.pDynamicStates = dyn;
    }
    FixedFunctionState(const FixedFunctionState&) = delete;
    FixedFunctionState& operator=(const FixedFunctionState&) = delete;

    VkPipelineVertexInputStateCreateInfo vi =
        vk_struct<VkPipelineVertexInputStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO);
    VkPipelineInputAssemblyStateCreateInfo ia =
        vk_struct<VkPipelineInputAssemblyStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO);
    VkPipelineViewportStateCreateInfo vp =
        vk_struct<VkPipelineViewportStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO);
    VkPipelineRasterizationStateCreateInfo rs =
        vk_struct<VkPipelineRasterizationStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO);
    VkPipelineMultisampleStateCreateInfo ms =
        vk_struct<VkPipelineMultisampleStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO);
    VkPipelineDepthStencilStateCreateInfo ds =
        vk_struct<VkPipelineDepthStencilStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO);
    VkPipelineColorBlendAttachmentState blend{};
    VkPipelineColorBlendStateCreateInfo cb =
        vk_struct<VkPipelineColorBlendStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO);
    VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dy =
        vk_struct<VkPipelineDynamicStateCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO);
};

VkPipeline create_pipeline(VkDevice dev, const GraphicsPipelineDesc& d, const VkPipelineShaderStageCreateInfo (&stages)[2],
                           VkPipelineLayout layout, VkRenderPass render_pass) {
    const FixedFunctionState f(d);
    auto ci = vk_struct<VkGraphicsPipelineCreateInfo>(VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO);
    ci.stageCount = 2;
    ci.pStages = stages;
    ci.pVertexInputState = &f.vi;
    ci.pInputAssemblyState = &f.ia;
    ci.pViewportState = &f.vp;
    ci.pRasterizationState = &f.rs;
    ci.pMultisampleState = &f.ms;
    ci.pDepthStencilState = &f.ds;
    ci.pColorBlendState = &f.cb;
    ci.pDynamicState = &f.dy;
    ci.layout = layout;
    ci.renderPass = render_pass;
    ci.subpass = 0;
    VkPipeline pipeline = VK_NULL_HANDLE;
    check(vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline), "vkCreateGraphicsPipelines");
    return pipeline;
}

} // namespace

void require_target_support(const Context& ctx, const TargetFormat& format) {
    const DeviceInfo& info = ctx.info();
    const std::string dev = info.device_name + ": ";
    if (!info.graphics) throw EnvironmentError(dev + "no queue that runs both compute and graphics");
    if (!(info.color_sample_counts & format.samples) || !(info.depth_sample_counts & format.samples))
        throw EnvironmentError(dev + std::to_string(int(format.samples)) + "x multisampled framebuffers are not supported");
    if (format.samples != VK_SAMPLE_COUNT_1_BIT && !info.standard_sample_locations)
        throw EnvironmentError(dev + "no standard sample locations (the fragment path's coverage assumes them)");
    if (!ctx.format_supports(format.color, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT))
        throw EnvironmentError(dev + "the colour format is not renderable");
    if (!ctx.format_supports(format.depth, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT))
        throw EnvironmentError(dev + "the depth format is not renderable");
}

OffscreenTarget::Attachment OffscreenTarget::make_attachment(VkFormat format, VkSampleCountFlagBits samples,
                                                             VkImageUsageFlags usage, VkImageAspectFlags aspect) {
    VkDevice dev = ctx_.device();
    Attachment a;
    auto ici = vk_struct<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {width_, height_, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = samples;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check(vkCreateImage(dev, &ici, nullptr, &a.image), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(dev, a.image, &req);
    auto ai = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = ctx_.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check(vkAllocateMemory(dev, &ai, nullptr, &a.memory), "vkAllocateMemory");
    check(vkBindImageMemory(dev, a.image, a.memory, 0), "vkBindImageMemory");
    auto vci = vk_struct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    vci.image = a.image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {aspect, 0, 1, 0, 1};
    check(vkCreateImageView(dev, &vci, nullptr, &a.view), "vkCreateImageView");
    return a;
}

void OffscreenTarget::destroy(Attachment& a) {
    VkDevice dev = ctx_.device();
    if (a.view) vkDestroyImageView(dev, a.view, nullptr);
    if (a.image) vkDestroyImage(dev, a.image, nullptr);
    if (a.memory) vkFreeMemory(dev, a.memory, nullptr);
    a = {};
}

OffscreenTarget::OffscreenTarget(Context& ctx, uint32_t width, uint32_t height, const TargetFormat& format)
    : ctx_(ctx), width_(width), height_(height), format_(format) {
    require_target_support(ctx, format);
    const bool msaa = format.samples != VK_SAMPLE_COUNT_1_BIT;
    try {
        VkImageUsageFlags color_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
        if (!msaa) color_usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT; // copied directly: nothing to resolve
        color_ = make_attachment(format.color, format.samples, color_usage, VK_IMAGE_ASPECT_COLOR_BIT);
        depth_ =
            make_attachment(format.depth, format.samples, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
        if (msaa)
            resolve_ =
                make_attachment(format.color, VK_SAMPLE_COUNT_1_BIT,
                                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
        render_pass_ = create_render_pass(ctx.device(), format);
        VkImageView views[3] = {color_.view, depth_.view, resolve_.view};
        auto fci = vk_struct<VkFramebufferCreateInfo>(VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO);
        fci.renderPass = render_pass_;
        fci.attachmentCount = msaa ? 3 : 2;
        fci.pAttachments = views;
        fci.width = width;
        fci.height = height;
        fci.layers = 1;
        check(vkCreateFramebuffer(ctx.device(), &fci, nullptr, &framebuffer_), "vkCreateFramebuffer");
    } catch (...) {
        release();
        throw;
    }
}

OffscreenTarget::~OffscreenTarget() { release(); }

void OffscreenTarget::release() {
    VkDevice dev = ctx_.device();
    if (framebuffer_) vkDestroyFramebuffer(dev, framebuffer_, nullptr);
    if (render_pass_) vkDestroyRenderPass(dev, render_pass_, nullptr);
    framebuffer_ = VK_NULL_HANDLE;
    render_pass_ = VK_NULL_HANDLE;
    destroy(color_);
    destroy(depth_);
    destroy(resolve_);
}

void OffscreenTarget::begin(VkCommandBuffer cmd, const std::array<float, 4>& clear) const {
    VkClearValue clears[3] = {};
    for (int i = 0; i < 4; ++i) clears[0].color.float32[i] = clear[size_t(i)];
    clears[1].depthStencil = {1.0f, 0};
    clears[2] = clears[0];
    auto bi = vk_struct<VkRenderPassBeginInfo>(VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO);
    bi.renderPass = render_pass_;
    bi.framebuffer = framebuffer_;
    bi.renderArea = {{0, 0}, {width_, height_}};
    bi.clearValueCount = format_.samples != VK_SAMPLE_COUNT_1_BIT ? 3 : 2;
    bi.pClearValues = clears;
    vkCmdBeginRenderPass(cmd, &bi, VK_SUBPASS_CONTENTS_INLINE);
    VkViewport vp{0, 0, float(width_), float(height_), 0, 1};
    VkRect2D scissor{{0, 0}, {width_, height_}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void OffscreenTarget::end(VkCommandBuffer cmd) const { vkCmdEndRenderPass(cmd); }

void OffscreenTarget::copy_resolved(VkCommandBuffer cmd, const Buffer& dst) const {
    VkDeviceSize bytes = VkDeviceSize(width_) * height_ * texel_bytes(format_.color);
    if (dst.size < bytes) throw Error("OffscreenTarget::copy_resolved: buffer too small");
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    r.imageExtent = {width_, height_, 1};
    VkImage src = format_.samples != VK_SAMPLE_COUNT_1_BIT ? resolve_.image : color_.image;
    vkCmdCopyImageToBuffer(cmd, src, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.buffer, 1, &r);
    Context::barrier(cmd);
}

GraphicsPipeline::GraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& d) : ctx_(ctx) {
    if (!d.vertex || !d.fragment) throw Error("GraphicsPipeline: a vertex and a fragment shader are needed");
    VkDevice dev = ctx.device();
    counts_ = d.vertex->counts_instructions || d.fragment->counts_instructions;
    if (counts_ && !ctx.info().graphics_stores)
        throw EnvironmentError(
            ctx.info().device_name +
            ": counting a draw's instructions needs vertexPipelineStoresAndAtomics and fragmentStoresAndAtomics");
    const std::vector<VkDescriptorSetLayoutBinding> bindings = layout_bindings(d.bindings, counts_, kStages, "GraphicsPipeline");
    try {
        set_layout_ = create_set_layout(dev, bindings);
        layout_ = create_pipeline_layout(dev, set_layout_, d.push_constant_bytes, kStages);
        render_pass_ = create_render_pass(dev, d.target);
        StageModules modules(dev); // destroyed once the pipeline holds the code, or on failure
        const VkPipelineShaderStageCreateInfo stages[2] = {modules.create(VK_SHADER_STAGE_VERTEX_BIT, *d.vertex),
                                                           modules.create(VK_SHADER_STAGE_FRAGMENT_BIT, *d.fragment)};
        pipeline_ = create_pipeline(dev, d, stages, layout_, render_pass_);
    } catch (...) {
        release();
        throw;
    }
}

GraphicsPipeline::~GraphicsPipeline() { release(); }

void GraphicsPipeline::release() {
    VkDevice dev = ctx_.device();
    if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
    if (render_pass_) vkDestroyRenderPass(dev, render_pass_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
    pipeline_ = VK_NULL_HANDLE;
    render_pass_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    set_layout_ = VK_NULL_HANDLE;
}

void GraphicsPipeline::draw(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push, uint32_t push_bytes,
                            uint32_t vertex_count, uint32_t instance_count) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
    ctx_.push_descriptors(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, bindings);
    if (push && push_bytes) vkCmdPushConstants(cmd, layout_, kStages, 0, push_bytes, push);
    vkCmdDraw(cmd, vertex_count, instance_count, 0, 0);
}

} // namespace iblcheck::vk
