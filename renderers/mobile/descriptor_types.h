// Short names for the descriptor types the Vulkan methods bind, declared once for every file of the
// target (two files each declaring them collide in one unity batch).
#pragma once
#include <vulkan/vulkan.h>

namespace iblcheck {

inline constexpr VkDescriptorType kSampled = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
inline constexpr VkDescriptorType kStorageImage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
inline constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
inline constexpr VkDescriptorType kUniformBuffer = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;

} // namespace iblcheck
