// The layouts the compute and graphics pipelines share (compute_pipeline.cpp): set 0 as push
// descriptors, one push-constant range, and the instruction counter's binding when a shader counts.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace iblcheck::vk {

// Binding i of type bindings[i] in `stages`, plus the instruction counter's (kCostBinding) when `counts`;
// throws Error naming `owner` when a binding takes the counter's slot.
std::vector<VkDescriptorSetLayoutBinding> layout_bindings(const std::vector<VkDescriptorType>& bindings, bool counts,
                                                          VkShaderStageFlags stages, const char* owner);
VkDescriptorSetLayout create_set_layout(VkDevice dev, const std::vector<VkDescriptorSetLayoutBinding>& bindings);
// Set 0 and, when `push_constant_bytes` > 0, one push-constant range `stages` see.
VkPipelineLayout create_pipeline_layout(VkDevice dev, VkDescriptorSetLayout set_layout, uint32_t push_constant_bytes,
                                        VkShaderStageFlags stages);

} // namespace iblcheck::vk
