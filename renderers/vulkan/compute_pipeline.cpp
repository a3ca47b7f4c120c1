// Compute pipelines with push descriptors and push constants, and what the compute and graphics
// pipelines share: their layouts (pipeline_layout.h) and the descriptor writes (Context::push_descriptors).
#include "context.h"
#include "kernel/errors.h"
#include "pipeline_layout.h"
#include "spirv_cost.h"
#include "vk_struct.h"

namespace iblcheck::vk {

std::vector<VkDescriptorSetLayoutBinding> layout_bindings(const std::vector<VkDescriptorType>& bindings, bool counts,
                                                          VkShaderStageFlags stages, const char* owner) {
    std::vector<VkDescriptorSetLayoutBinding> lb;
    for (uint32_t i = 0; i < bindings.size(); ++i) lb.push_back({i, bindings[i], 1, stages, nullptr});
    if (counts && bindings.size() > kCostBinding)
        throw Error(std::string(owner) + ": binding " + std::to_string(kCostBinding) + " is the instruction counter's");
    if (counts) lb.push_back({kCostBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr});
    return lb;
}

VkDescriptorSetLayout create_set_layout(VkDevice dev, const std::vector<VkDescriptorSetLayoutBinding>& bindings) {
    auto dl = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    dl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    dl.bindingCount = uint32_t(bindings.size());
    dl.pBindings = bindings.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    check(vkCreateDescriptorSetLayout(dev, &dl, nullptr, &layout), "vkCreateDescriptorSetLayout");
    return layout;
}

VkPipelineLayout create_pipeline_layout(VkDevice dev, VkDescriptorSetLayout set_layout, uint32_t push_constant_bytes,
                                        VkShaderStageFlags stages) {
    VkPushConstantRange pcr{stages, 0, push_constant_bytes};
    auto pl = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout;
    pl.pushConstantRangeCount = push_constant_bytes ? 1 : 0;
    pl.pPushConstantRanges = &pcr;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    check(vkCreatePipelineLayout(dev, &pl, nullptr, &layout), "vkCreatePipelineLayout");
    return layout;
}

ComputePipeline::ComputePipeline(Context& ctx, const CompiledShader& shader, const std::vector<VkDescriptorType>& bindings,
                                 uint32_t push_constant_bytes, const std::vector<SpecConstant>& spec)
    : ctx_(ctx), push_bytes_(push_constant_bytes) {
    VkDevice dev = ctx.device();
    set_layout_ = create_set_layout(
        dev, layout_bindings(bindings, shader.counts_instructions, VK_SHADER_STAGE_COMPUTE_BIT, "ComputePipeline"));
    layout_ = create_pipeline_layout(dev, set_layout_, push_constant_bytes, VK_SHADER_STAGE_COMPUTE_BIT);

    auto smi = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    smi.codeSize = shader.spirv.size() * 4;
    smi.pCode = shader.spirv.data();
    VkShaderModule module;
    check(vkCreateShaderModule(dev, &smi, nullptr, &module), "vkCreateShaderModule");
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> data;
    for (auto& s : spec) {
        entries.push_back({s.id, uint32_t(data.size() * 4), 4});
        data.push_back(s.value);
    }
    VkSpecializationInfo si{uint32_t(entries.size()), entries.data(), data.size() * 4, data.data()};
    auto ci = vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    ci.stage = vk_struct<decltype(ci.stage)>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = entries.empty() ? nullptr : &si;
    ci.layout = layout_;
    VkResult r = vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline_);
    vkDestroyShaderModule(dev, module, nullptr);
    check(r, "vkCreateComputePipelines");
}

std::vector<std::pair<std::string, double>> ComputePipeline::dispatch_timed(const std::string& name,
                                                                            const std::vector<Binding>& bindings,
                                                                            const void* push, uint32_t push_bytes, uint32_t gx,
                                                                            uint32_t gy, uint32_t gz) const {
    GpuTimer timer(ctx_, 1);
    ctx_.submit([&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        warm_up(cmd, bindings, push, push_bytes);
        timer.begin(cmd, name);
        dispatch(cmd, bindings, push, push_bytes, gx, gy, gz);
        timer.end(cmd);
        Context::barrier(cmd);
    });
    return timer.results();
}

ComputePipeline::~ComputePipeline() {
    VkDevice dev = ctx_.device();
    if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
}

void Context::push_descriptors(VkCommandBuffer cmd, VkPipelineBindPoint bind_point, VkPipelineLayout layout,
                               const std::vector<Binding>& bindings) const {
    if (bindings.empty()) return; // zero writes is invalid usage
    std::vector<VkWriteDescriptorSet> writes(bindings.size());
    std::vector<VkDescriptorBufferInfo> bufs(bindings.size());
    std::vector<VkDescriptorImageInfo> imgs(bindings.size());
    for (size_t i = 0; i < bindings.size(); ++i) {
        const Binding& b = bindings[i];
        VkWriteDescriptorSet& w = writes[i];
        w = vk_struct<decltype(w)>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        w.dstBinding = b.binding;
        w.descriptorCount = 1;
        w.descriptorType = b.type;
        if (b.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
            bufs[i] = {b.buffer, 0, VK_WHOLE_SIZE};
            w.pBufferInfo = &bufs[i];
        } else {
            imgs[i] = {b.sampler, b.view, b.layout};
            w.pImageInfo = &imgs[i];
        }
    }
    push_descriptor_fn_(cmd, bind_point, layout, 0, uint32_t(writes.size()), writes.data());
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push, uint32_t push_bytes,
                               uint32_t gx, uint32_t gy, uint32_t gz) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    ctx_.push_descriptors(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, bindings);
    if (push && push_bytes) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, push);
    vkCmdDispatch(cmd, gx, gy, gz);
}

void ComputePipeline::warm_up(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push,
                              uint32_t push_bytes) const {
    if (warmed_) return;
    warmed_ = true;
    dispatch(cmd, bindings, push, push_bytes, 1, 1, 1);
    Context::barrier(cmd);
}

} // namespace iblcheck::vk
