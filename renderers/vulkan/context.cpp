#include "context.h"

#include <cstring>
#include <regex>

#include "kernel/errors.h"
#include "vk_struct.h"

namespace iblcheck::vk {

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

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
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

std::string describe(const DeviceEntry& e) { return std::string(e.props.deviceName) + " [driver " + e.driver.driverName + "]"; }

VkDebugUtilsMessengerEXT create_messenger(VkInstance instance, Context* ctx) {
    auto mi = vk_struct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = debug_callback;
    mi.pUserData = ctx;
    auto fn =
        reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    if (fn) check(fn(instance, &mi, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    return messenger;
}

// The device `wanted` names (a part of its name or its driver's), or by default llvmpipe, else the
// first device; EnvironmentError listing `available` when nothing matches.
const DeviceEntry& choose_device(const std::vector<DeviceEntry>& devices, const std::string& wanted,
                                 const std::vector<std::string>& available) {
    for (auto& e : devices) {
        std::string name = e.props.deviceName, drv = e.driver.driverName;
        bool match = wanted.empty()
                         ? (e.driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE || name.find("llvmpipe") != std::string::npos)
                         : (name.find(wanted) != std::string::npos || drv.find(wanted) != std::string::npos);
        if (match) return e;
    }
    if (wanted.empty()) return devices.front();
    std::string list;
    for (auto& d : available) list += "\n  " + d;
    throw EnvironmentError("no Vulkan device matches --device '" + wanted + "'; available:" + list);
}

// Names, versions and limits of the chosen device, for provenance and for the passes.
void describe_device(const DeviceEntry& chosen, DeviceInfo& info) {
    info.device_name = chosen.props.deviceName;
    info.driver_name = chosen.driver.driverName;
    info.driver_info = chosen.driver.driverInfo;
    info.api_version = version_string(chosen.props.apiVersion);
    info.device_type = type_name(chosen.props.deviceType);
    info.vendor_id = chosen.props.vendorID;
    info.device_id = chosen.props.deviceID;
    info.timestamp_period_ns = chosen.props.limits.timestampPeriod;
    // Compiled once: the runner's workers create contexts concurrently, and compiling a
    // std::regex races on libstdc++'s ctype cache (found by TSan, issue 15).
    static const std::regex mesa_re(R"(Mesa ([0-9][0-9.]*[0-9](-[a-z0-9]+)?))");
    static const std::regex llvm_re(R"(LLVM ([0-9][0-9.]*[0-9]))");
    std::smatch m;
    if (std::regex_search(info.driver_info, m, mesa_re)) info.mesa_version = m[1];
    std::string both = info.driver_info + " " + info.device_name;
    if (std::regex_search(both, m, llvm_re)) info.llvm_version = m[1];
    info.standard_sample_locations = chosen.props.limits.standardSampleLocations;
    info.color_sample_counts = chosen.props.limits.framebufferColorSampleCounts;
    info.depth_sample_counts = chosen.props.limits.framebufferDepthSampleCounts;
}

// Queue family with compute, preferably graphics too (shading=fragment draws on it).
uint32_t choose_queue_family(const DeviceEntry& chosen, DeviceInfo& info) {
    uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(chosen.pd, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> qf(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(chosen.pd, &nq, qf.data());
    for (bool need_graphics : {true, false})
        for (uint32_t i = 0; i < nq; ++i)
            if ((qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && (!need_graphics || (qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT))) {
                info.timestamps = qf[i].timestampValidBits > 0 && chosen.props.limits.timestampComputeAndGraphics;
                info.graphics = need_graphics;
                return i;
            }
    throw EnvironmentError(info.device_name + ": no compute queue");
}

// The logical device with one queue of `queue_family`, VK_KHR_push_descriptor, and the features the
// harness uses when the device has them: float16 arithmetic (precision=mediump), 16-bit storage,
// 64-bit integers and atomics and stores from graphics stages (instruction counting).
VkDevice create_device(VkPhysicalDevice pd, uint32_t queue_family, DeviceInfo& info) {
    auto f11 = vk_struct<VkPhysicalDeviceVulkan11Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES);
    auto f12 = vk_struct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    f11.pNext = &f12;
    auto f2 = vk_struct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
    f2.pNext = &f11;
    vkGetPhysicalDeviceFeatures2(pd, &f2);
    info.shader_float16 = f12.shaderFloat16;
    info.storage_16bit = f11.storageBuffer16BitAccess;
    info.int64_atomics = f2.features.shaderInt64 && f12.shaderBufferInt64Atomics;
    info.graphics_stores = f2.features.vertexPipelineStoresAndAtomics && f2.features.fragmentStoresAndAtomics;

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
    e2.features.shaderInt64 = f2.features.shaderInt64; // instruction counting
    e12.shaderBufferInt64Atomics = f12.shaderBufferInt64Atomics;
    e2.features.vertexPipelineStoresAndAtomics = f2.features.vertexPipelineStoresAndAtomics; // counting a draw
    e2.features.fragmentStoresAndAtomics = f2.features.fragmentStoresAndAtomics;

    float prio = 1.0f;
    auto qci = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    qci.queueFamilyIndex = queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    const char* dev_exts[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    auto dci = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    dci.pNext = &e2;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = 1;
    dci.ppEnabledExtensionNames = dev_exts;
    VkDevice device = VK_NULL_HANDLE;
    VkResult r = vkCreateDevice(pd, &dci, nullptr, &device);
    if (r == VK_ERROR_EXTENSION_NOT_PRESENT)
        throw EnvironmentError(info.device_name + ": VK_KHR_push_descriptor is required and not supported");
    check(r, "vkCreateDevice");
    return device;
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
        if (validation) messenger_ = create_messenger(instance_, this);
        auto devices = enumerate(instance_);
        if (devices.empty()) throw EnvironmentError(kNoDriverHelp);
        for (auto& e : devices) info_.available_devices.push_back(describe(e));
        const DeviceEntry& chosen = choose_device(devices, options.device, info_.available_devices);
        physical_ = chosen.pd;
        describe_device(chosen, info_);
        info_.validation = validation;
        queue_family_ = choose_queue_family(chosen, info_);
        device_ = create_device(physical_, queue_family_, info_);
        vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
        push_descriptor_fn_ =
            reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
        create_pool_and_samplers();
    } catch (...) {
        destroy(); // the destructor does not run for a constructor that throws
        throw;
    }
}

void Context::create_pool_and_samplers() {
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

} // namespace iblcheck::vk
