#include "context.h"

#include <type_traits>

#include <cstring>
#include <regex>

#include "harness/common/errors.h"
#include "spirv_cost.h"

namespace iblcheck::vk {

// A Vulkan info struct with its sType set and every other member zero (value-initialised, so
// -Wmissing-field-initializers has nothing to say).
template <class T> std::remove_cvref_t<T> vk_struct(VkStructureType type) {
    std::remove_cvref_t<T> t{};
    t.sType = type;
    return t;
}


namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kNoDriverHelp =
    "no Vulkan driver found: install Mesa's lavapipe with scripts/setup.sh (package mesa-vulkan-drivers), "
    "and check that VK_ICD_FILENAMES / VK_DRIVER_FILES, if set, name an existing ICD json";

std::string result_name(VkResult r) {
    switch (r) {
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    default: return "VkResult " + std::to_string(int(r));
    }
}

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    static_cast<Context*>(user)->on_validation_message(int(severity), data->pMessage);
    return VK_FALSE;
}

bool has_layer(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> layers(n);
    vkEnumerateInstanceLayerProperties(&n, layers.data());
    for (auto& l : layers)
        if (std::strcmp(l.layerName, name) == 0) return true;
    return false;
}

std::string version_string(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

const char* type_name(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual-gpu";
    default: return "other";
    }
}

VkInstance create_instance(bool validation) {
    auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "iblcheck";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> layers, exts;
    if (validation) {
        layers.push_back(kValidationLayer);
        exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    auto ci = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(exts.size());
    ci.ppEnabledExtensionNames = exts.data();
    VkInstance inst = VK_NULL_HANDLE;
    VkResult r = vkCreateInstance(&ci, nullptr, &inst);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED) throw EnvironmentError(kNoDriverHelp);
    if (r != VK_SUCCESS) throw EnvironmentError("vkCreateInstance failed: " + result_name(r));
    return inst;
}

struct DeviceEntry {
    VkPhysicalDevice pd;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceDriverProperties driver;
};

std::vector<DeviceEntry> enumerate(VkInstance inst) {
    uint32_t n = 0;
    VkResult r = vkEnumeratePhysicalDevices(inst, &n, nullptr);
    if (r != VK_SUCCESS && r != VK_INCOMPLETE) throw EnvironmentError(kNoDriverHelp);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(inst, &n, pds.data());
    std::vector<DeviceEntry> out;
    for (auto pd : pds) {
        DeviceEntry e{};
        e.pd = pd;
        e.driver = vk_struct<decltype(e.driver)>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
        auto p2 = vk_struct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
        p2.pNext = &e.driver;
        vkGetPhysicalDeviceProperties2(pd, &p2);
        e.props = p2.properties;
        out.push_back(e);
    }
    return out;
}

std::string describe(const DeviceEntry& e) {
    return std::string(e.props.deviceName) + " [driver " + e.driver.driverName + "]";
}

} // namespace

void check(VkResult r, const char* what) {
    if (r != VK_SUCCESS) throw EnvironmentError(std::string(what) + " failed: " + result_name(r));
}

SpecConstant spec_float(uint32_t id, float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    return {id, bits};
}

std::vector<std::string> list_devices() {
    VkInstance inst = create_instance(false);
    std::vector<std::string> out;
    try {
        for (auto& e : enumerate(inst)) out.push_back(describe(e));
    } catch (...) {
        vkDestroyInstance(inst, nullptr);
        throw;
    }
    vkDestroyInstance(inst, nullptr);
    return out;
}

Context::Context(const ContextOptions& options) {
    bool validation = options.validation;
    if (validation && !has_layer(kValidationLayer))
        throw EnvironmentError("validation requested but VK_LAYER_KHRONOS_validation is not installed "
                               "(package vulkan-validationlayers; run scripts/setup.sh)");
    instance_ = create_instance(validation);
    try {
        if (validation) {
            auto mi = vk_struct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
            mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
            mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
            mi.pfnUserCallback = debug_callback;
            mi.pUserData = this;
            auto fn = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            if (fn) check(fn(instance_, &mi, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
        }

        auto devices = enumerate(instance_);
        if (devices.empty()) throw EnvironmentError(kNoDriverHelp);
        for (auto& e : devices) info_.available_devices.push_back(describe(e));
        const DeviceEntry* chosen = nullptr;
        for (auto& e : devices) {
            std::string name = e.props.deviceName, drv = e.driver.driverName;
            bool match = options.device.empty()
                             ? (e.driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE || name.find("llvmpipe") != std::string::npos)
                             : (name.find(options.device) != std::string::npos || drv.find(options.device) != std::string::npos);
            if (match) {
                chosen = &e;
                break;
            }
        }
        if (!chosen && options.device.empty()) chosen = &devices.front();
        if (!chosen) {
            std::string list;
            for (auto& d : info_.available_devices) list += "\n  " + d;
            throw EnvironmentError("no Vulkan device matches --device '" + options.device + "'; available:" + list);
        }
        physical_ = chosen->pd;
        info_.device_name = chosen->props.deviceName;
        info_.driver_name = chosen->driver.driverName;
        info_.driver_info = chosen->driver.driverInfo;
        info_.api_version = version_string(chosen->props.apiVersion);
        info_.device_type = type_name(chosen->props.deviceType);
        info_.vendor_id = chosen->props.vendorID;
        info_.device_id = chosen->props.deviceID;
        info_.timestamp_period_ns = chosen->props.limits.timestampPeriod;
        info_.validation = validation;
        std::smatch m;
        if (std::regex_search(info_.driver_info, m, std::regex(R"(Mesa ([0-9][0-9.]*[0-9](-[a-z0-9]+)?))")))
            info_.mesa_version = m[1];
        std::string both = info_.driver_info + " " + info_.device_name;
        if (std::regex_search(both, m, std::regex(R"(LLVM ([0-9][0-9.]*[0-9]))"))) info_.llvm_version = m[1];

        // Queue family with compute.
        uint32_t nq = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, nullptr);
        std::vector<VkQueueFamilyProperties> qf(nq);
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nq, qf.data());
        bool found = false;
        for (uint32_t i = 0; i < nq; ++i)
            if (qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                queue_family_ = i;
                info_.timestamps = qf[i].timestampValidBits > 0 && chosen->props.limits.timestampComputeAndGraphics;
                found = true;
                break;
            }
        if (!found) throw EnvironmentError(info_.device_name + ": no compute queue");

        // Features the harness uses: float16 arithmetic (precision=mediump) and 16-bit storage.
        auto f11 = vk_struct<VkPhysicalDeviceVulkan11Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES);
        auto f12 = vk_struct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
        f11.pNext = &f12;
        auto f2 = vk_struct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
        f2.pNext = &f11;
        vkGetPhysicalDeviceFeatures2(physical_, &f2);
        info_.shader_float16 = f12.shaderFloat16;
        info_.storage_16bit = f11.storageBuffer16BitAccess;
        info_.int64_atomics = f2.features.shaderInt64 && f12.shaderBufferInt64Atomics;

        auto e11 = vk_struct<VkPhysicalDeviceVulkan11Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES);
        auto e12 = vk_struct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
        e11.pNext = &e12;
        e11.storageBuffer16BitAccess = f11.storageBuffer16BitAccess;
        e12.shaderFloat16 = f12.shaderFloat16;
        e12.hostQueryReset = f12.hostQueryReset;
        auto e2 = vk_struct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
        e2.pNext = &e11;
        e2.features.shaderInt16 = f2.features.shaderInt16;
        e2.features.shaderFloat64 = f2.features.shaderFloat64;
        e2.features.shaderInt64 = f2.features.shaderInt64;                  // instruction counting
        e12.shaderBufferInt64Atomics = f12.shaderBufferInt64Atomics;

        float prio = 1.0f;
        auto qci = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        qci.queueFamilyIndex = queue_family_;
        qci.queueCount = 1;
        qci.pQueuePriorities = &prio;
        const char* dev_exts[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
        auto dci = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        dci.pNext = &e2;
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &qci;
        dci.enabledExtensionCount = 1;
        dci.ppEnabledExtensionNames = dev_exts;
        VkResult r = vkCreateDevice(physical_, &dci, nullptr, &device_);
        if (r == VK_ERROR_EXTENSION_NOT_PRESENT)
            throw EnvironmentError(info_.device_name + ": VK_KHR_push_descriptor is required and not supported");
        check(r, "vkCreateDevice");
        vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
        push_descriptor_fn_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
            vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));

        auto pci = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pci.queueFamilyIndex = queue_family_;
        check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
        auto fci = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
        check(vkCreateFence(device_, &fci, nullptr, &fence_), "vkCreateFence");

        auto sci = vk_struct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
        sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
        sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
        sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        sci.maxLod = VK_LOD_CLAMP_NONE;
        check(vkCreateSampler(device_, &sci, nullptr, &linear_sampler_), "vkCreateSampler");
        sci.addressModeU = VK_SAMPLER_ADDRESS_MODE_REPEAT; // equirect: wraps in longitude
        check(vkCreateSampler(device_, &sci, nullptr, &equirect_sampler_), "vkCreateSampler");
        sci.addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
        sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        check(vkCreateSampler(device_, &sci, nullptr, &nearest_sampler_), "vkCreateSampler");
    } catch (...) {
        destroy();  // the destructor does not run for a constructor that throws
        throw;
    }
}

Context::~Context() { destroy(); }

void Context::destroy() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        for (VkSampler s : {linear_sampler_, equirect_sampler_, nearest_sampler_})
            if (s) vkDestroySampler(device_, s, nullptr);
        if (fence_) vkDestroyFence(device_, fence_, nullptr);
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
    }
    if (messenger_) {
        auto fn = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (fn) fn(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

void Context::on_validation_message(int severity, const char* message) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        ++validation_errors_;
        validation_messages_.emplace_back(message);
    }
}

uint32_t Context::find_memory_type(uint32_t bits, VkMemoryPropertyFlags props) const {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & props) == props) return i;
    throw EnvironmentError(info_.device_name + ": no suitable memory type");
}

bool Context::format_supports(VkFormat format, VkFormatFeatureFlags features) const {
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(physical_, format, &fp);
    return (fp.optimalTilingFeatures & features) == features;
}

Buffer Context::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer b;
    b.ctx = this;
    b.size = size;
    auto bci = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    bci.size = size;
    bci.usage = usage;
    check(vkCreateBuffer(device_, &bci, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, b.buffer, &req);
    auto ai = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                                  VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check(vkAllocateMemory(device_, &ai, nullptr, &b.memory), "vkAllocateMemory");
    check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
    check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    std::memset(b.mapped, 0, size);
    return b;
}

Image Context::create_image(VkFormat format, uint32_t width, uint32_t height, uint32_t mips, bool cube) {
    Image img;
    img.ctx = this;
    img.format = format;
    img.width = width;
    img.height = height;
    img.mips = mips;
    img.layers = cube ? 6 : 1;
    img.cube = cube;
    auto ici = vk_struct<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
    ici.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {width, height, 1};
    ici.mipLevels = mips;
    ici.arrayLayers = img.layers;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check(vkCreateImage(device_, &ici, nullptr, &img.image), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, img.image, &req);
    auto ai = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check(vkAllocateMemory(device_, &ai, nullptr, &img.memory), "vkAllocateMemory");
    check(vkBindImageMemory(device_, img.image, img.memory, 0), "vkBindImageMemory");

    auto vci = vk_struct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    vci.image = img.image;
    vci.viewType = cube ? VK_IMAGE_VIEW_TYPE_CUBE : VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mips, 0, img.layers};
    check(vkCreateImageView(device_, &vci, nullptr, &img.sampled_view), "vkCreateImageView");
    for (uint32_t m = 0; m < mips; ++m) {
        vci.viewType = cube ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
        vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, m, 1, 0, img.layers};
        VkImageView v;
        check(vkCreateImageView(device_, &vci, nullptr, &v), "vkCreateImageView");
        img.storage_views.push_back(v);
    }
    return img;
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    std::swap(ctx, o.ctx);
    std::swap(buffer, o.buffer);
    std::swap(memory, o.memory);
    std::swap(size, o.size);
    std::swap(mapped, o.mapped);
    return *this;
}

Buffer::~Buffer() {
    if (!ctx) return;
    if (buffer) vkDestroyBuffer(ctx->device(), buffer, nullptr);
    if (memory) vkFreeMemory(ctx->device(), memory, nullptr);
}

Image& Image::operator=(Image&& o) noexcept {
    std::swap(ctx, o.ctx);
    std::swap(image, o.image);
    std::swap(memory, o.memory);
    std::swap(format, o.format);
    std::swap(width, o.width);
    std::swap(height, o.height);
    std::swap(mips, o.mips);
    std::swap(layers, o.layers);
    std::swap(cube, o.cube);
    std::swap(sampled_view, o.sampled_view);
    std::swap(storage_views, o.storage_views);
    return *this;
}

Image::~Image() {
    if (!ctx) return;
    for (auto v : storage_views) vkDestroyImageView(ctx->device(), v, nullptr);
    if (sampled_view) vkDestroyImageView(ctx->device(), sampled_view, nullptr);
    if (image) vkDestroyImage(ctx->device(), image, nullptr);
    if (memory) vkFreeMemory(ctx->device(), memory, nullptr);
}

VkCommandBuffer Context::begin_commands() {
    auto ai = vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    check(vkAllocateCommandBuffers(device_, &ai, &cmd), "vkAllocateCommandBuffers");
    auto bi = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
    return cmd;
}

void Context::end_and_wait(VkCommandBuffer cmd) {
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    auto si = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    check(vkQueueSubmit(queue_, 1, &si, fence_), "vkQueueSubmit");
    check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(vkResetFences(device_, 1, &fence_), "vkResetFences");
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

void Context::barrier(VkCommandBuffer cmd) {
    auto mb = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                       VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &mb, 0, nullptr, 0, nullptr);
}

void Context::transition(VkCommandBuffer cmd, const Image& img, VkImageLayout from, VkImageLayout to) {
    auto b = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img.image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, img.mips, 0, img.layers};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
}

void Context::copy_buffer_to_image(VkCommandBuffer cmd, const Buffer& src, const Image& dst, uint32_t mip) {
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, dst.layers};
    r.imageExtent = {std::max(1u, dst.width >> mip), std::max(1u, dst.height >> mip), 1};
    vkCmdCopyBufferToImage(cmd, src.buffer, dst.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
}

namespace {
float half_to_float(uint16_t h) {
    uint32_t sign = uint32_t(h >> 15) << 31, exp = (h >> 10) & 0x1f, mant = h & 0x3ff, bits;
    if (exp == 0) {
        if (mant == 0) bits = sign;
        else {  // subnormal
            int e = -1;
            do { ++e; mant <<= 1; } while (!(mant & 0x400));
            bits = sign | uint32_t(127 - 15 - e) << 23 | (mant & 0x3ff) << 13;
        }
    } else if (exp == 31) {
        bits = sign | 0x7f800000u | mant << 13;
    } else {
        bits = sign | (exp + 112) << 23 | mant << 13;
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}
} // namespace

std::vector<float> Context::download(const Image& img, uint32_t mip) {
    uint32_t w = std::max(1u, img.width >> mip), h = std::max(1u, img.height >> mip);
    size_t texels = size_t(w) * h * img.layers;
    size_t bpp = img.format == VK_FORMAT_R32G32B32A32_SFLOAT ? 16 : img.format == VK_FORMAT_R16G16B16A16_SFLOAT ? 8
               : img.format == VK_FORMAT_R16G16_SFLOAT ? 4 : 0;
    if (!bpp) throw Error("Context::download: unsupported image format");
    Buffer buf = create_buffer(texels * bpp, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    submit([&](VkCommandBuffer cmd) {
        barrier(cmd);
        VkBufferImageCopy r{};
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, img.layers};
        r.imageExtent = {w, h, 1};
        vkCmdCopyImageToBuffer(cmd, img.image, VK_IMAGE_LAYOUT_GENERAL, buf.buffer, 1, &r);
        barrier(cmd);
    });
    std::vector<float> out(texels * 4);
    if (bpp == 16) {
        std::memcpy(out.data(), buf.mapped, texels * 16);
    } else {
        const uint16_t* hp = static_cast<const uint16_t*>(buf.mapped);
        for (size_t i = 0; i < texels; ++i) {
            if (bpp == 8)
                for (int c = 0; c < 4; ++c) out[4 * i + c] = half_to_float(hp[4 * i + c]);
            else {
                out[4 * i] = half_to_float(hp[2 * i]);
                out[4 * i + 1] = half_to_float(hp[2 * i + 1]);
                out[4 * i + 2] = 0;
                out[4 * i + 3] = 1;
            }
        }
    }
    return out;
}

ComputePipeline::ComputePipeline(Context& ctx, const CompiledShader& shader,
                                 const std::vector<VkDescriptorType>& bindings, uint32_t push_constant_bytes,
                                 const std::vector<SpecConstant>& spec)
    : ctx_(ctx), push_bytes_(push_constant_bytes) {
    VkDevice dev = ctx.device();
    std::vector<VkDescriptorSetLayoutBinding> lb;
    for (uint32_t i = 0; i < bindings.size(); ++i)
        lb.push_back({i, bindings[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    if (shader.counts_instructions && bindings.size() > kCostBinding)
        throw Error("ComputePipeline: binding " + std::to_string(kCostBinding) + " is the instruction counter's");
    if (shader.counts_instructions)
        lb.push_back({kCostBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    auto dl = vk_struct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    dl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    dl.bindingCount = uint32_t(lb.size());
    dl.pBindings = lb.data();
    check(vkCreateDescriptorSetLayout(dev, &dl, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
    VkPushConstantRange pcr{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
    auto pl = vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout_;
    pl.pushConstantRangeCount = push_constant_bytes ? 1 : 0;
    pl.pPushConstantRanges = &pcr;
    check(vkCreatePipelineLayout(dev, &pl, nullptr, &layout_), "vkCreatePipelineLayout");

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

ComputePipeline::~ComputePipeline() {
    VkDevice dev = ctx_.device();
    if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push,
                               uint32_t push_bytes, uint32_t gx, uint32_t gy, uint32_t gz) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
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
    ctx_.push_descriptor_fn_(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, uint32_t(writes.size()), writes.data());
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

GpuTimer::GpuTimer(Context& ctx, uint32_t max_passes) : ctx_(ctx), max_(max_passes) {
    auto qi = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2 * max_passes;
    check(vkCreateQueryPool(ctx.device(), &qi, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
    if (pool_) vkDestroyQueryPool(ctx_.device(), pool_, nullptr);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
    vkCmdResetQueryPool(cmd, pool_, 0, 2 * max_);
    names_.clear();
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
    if (names_.size() >= max_) throw Error("GpuTimer: more passes than reserved");
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, uint32_t(2 * names_.size()));
    names_.push_back(name);
}

void GpuTimer::end(VkCommandBuffer cmd) {
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, uint32_t(2 * names_.size() - 1));
}

std::vector<std::pair<std::string, double>> GpuTimer::results() const {
    std::vector<std::pair<std::string, double>> out;
    if (names_.empty()) return out;
    std::vector<uint64_t> ts(2 * names_.size());
    check(vkGetQueryPoolResults(ctx_.device(), pool_, 0, uint32_t(ts.size()), ts.size() * 8, ts.data(), 8,
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    for (size_t i = 0; i < names_.size(); ++i)
        out.emplace_back(names_[i], double(ts[2 * i + 1] - ts[2 * i]) * ctx_.info().timestamp_period_ns * 1e-6);
    return out;
}

} // namespace iblcheck::vk
