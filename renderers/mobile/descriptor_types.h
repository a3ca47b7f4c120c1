// The descriptor types the mobile passes bind, named once for every file of the pipeline
// (unity builds compile several of them as one translation unit).
#pragma once
#include <vulkan/vulkan.h>

namespace iblcheck {
inline constexpr VkDescriptorType kSampled = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
inline constexpr VkDescriptorType kStorageImage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
inline constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
} // namespace iblcheck
