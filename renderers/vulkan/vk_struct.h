// A Vulkan info struct with its sType set and every other member zero (value-initialised, so
// -Wmissing-field-initializers has nothing to say). Shared by the files that fill Vulkan structs.
#pragma once
#include <vulkan/vulkan.h>

#include <type_traits>

namespace iblcheck::vk {
template <class T> std::remove_cvref_t<T> vk_struct(VkStructureType type) {
    std::remove_cvref_t<T> t{};
    t.sType = type;
    return t;
}
} // namespace iblcheck::vk
