// The Vulkan plumbing, nothing IBL-specific: a headless instance and device (no window system),
// device selection (lavapipe by default: deterministic and on every CI machine), validation with an
// error counter, buffers/images, compute pipelines with push descriptors, and timestamp queries.
// Graphics pipelines and offscreen MSAA targets are in graphics_pipeline.h. Defined by job:
// context.cpp (instance, device selection and creation), resources.cpp (buffers, images, commands,
// transfers), compute_pipeline.cpp, gpu_timer.cpp.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "shader_compiler.h"

namespace iblcheck::vk {

struct ContextOptions {
    // Substring of the device or driver name; empty: lavapipe (llvmpipe) if present, else the first.
    std::string device;
    // Enable VK_LAYER_KHRONOS_validation and count its errors (tests turn it on).
    bool validation = false;
};

struct DeviceInfo {
    std::string device_name;  // "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string driver_name;  // "llvmpipe"
    std::string driver_info;  // "Mesa 22.3.6 (LLVM 15.0.6)"
    std::string mesa_version; // "22.3.6" when the driver is Mesa's
    std::string llvm_version; // "15.0.6" when the driver reports one
    std::string api_version;  // "1.3.230"
    std::string device_type;  // "cpu", "discrete-gpu", ...
    uint32_t vendor_id = 0, device_id = 0;
    bool shader_float16 = false;
    bool storage_16bit = false;
    bool int64_atomics = false; // shaderInt64 + shaderBufferInt64Atomics: instruction counting (spirv_cost.h)
    bool graphics = false;      // the queue also runs graphics (graphics_pipeline.h)
    // vertexPipelineStoresAndAtomics + fragmentStoresAndAtomics: counting instructions of a draw
    bool graphics_stores = false;
    bool standard_sample_locations = false;
    VkSampleCountFlags color_sample_counts = 0, depth_sample_counts = 0; // framebuffer limits
    bool timestamps = false;
    double timestamp_period_ns = 1;
    bool validation = false;
    std::vector<std::string> available_devices;
};

// Lists the devices the loader finds (name + driver), without creating one.
std::vector<std::string> list_devices();

class Context;

struct Buffer {
    Context* ctx = nullptr;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* mapped = nullptr; // host-visible, coherent: written and read directly
    Buffer() = default;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    Buffer(Buffer&& o) noexcept { *this = std::move(o); }
    Buffer& operator=(Buffer&& o) noexcept;
    ~Buffer();
    template <class T> T* as() { return static_cast<T*>(mapped); }
};

struct Image {
    Context* ctx = nullptr;
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
    uint32_t width = 0, height = 0, mips = 1, layers = 1;
    bool cube = false;
    VkImageView sampled_view = VK_NULL_HANDLE; // whole image (cube or 2D)
    std::vector<VkImageView> storage_views;    // per mip: 2D-array view (cube) or 2D view
    Image() = default;
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;
    Image(Image&& o) noexcept { *this = std::move(o); }
    Image& operator=(Image&& o) noexcept;
    ~Image();
};

// One descriptor a dispatch binds, by binding number (set 0, push descriptors).
struct Binding {
    uint32_t binding;
    VkDescriptorType type;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkSampler sampler = VK_NULL_HANDLE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;
    static Binding storage_buffer(uint32_t b, const Buffer& buf) { return {b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buf.buffer}; }
    static Binding uniform_buffer(uint32_t b, const Buffer& buf) { return {b, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buf.buffer}; }
    static Binding storage_image(uint32_t b, VkImageView v) { return {b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_NULL_HANDLE, v}; }
    static Binding sampled_image(uint32_t b, VkImageView v, VkSampler s) {
        return {b, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_NULL_HANDLE, v, s};
    }
};

struct SpecConstant {
    uint32_t id;
    uint32_t value; // bit pattern: ints and floats both fit (see spec_float)
};
SpecConstant spec_float(uint32_t id, float v);

class ComputePipeline {
  public:
    ComputePipeline(Context& ctx, const CompiledShader& shader, const std::vector<VkDescriptorType>& bindings,
                    uint32_t push_constant_bytes, const std::vector<SpecConstant>& spec = {});
    ~ComputePipeline();
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;

    // llvmpipe compiles a shader variant at its first dispatch, not at pipeline creation: call this
    // before a timed region to record one untimed single-workgroup dispatch (once per pipeline), so
    // timestamps measure execution only. Its writes are overwritten by the real dispatch.
    void warm_up(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push, uint32_t push_bytes) const;

    // Records bind + push descriptors + push constants + dispatch.
    void dispatch(VkCommandBuffer cmd, const std::vector<Binding>& bindings, const void* push, uint32_t push_bytes, uint32_t gx,
                  uint32_t gy = 1, uint32_t gz = 1) const;

    // The timed pass a renderer reports: submits warm_up and one dispatch between timestamps named
    // `name` (GpuTimer), waits, and returns {name, milliseconds}.
    std::vector<std::pair<std::string, double>> dispatch_timed(const std::string& name, const std::vector<Binding>& bindings,
                                                               const void* push, uint32_t push_bytes, uint32_t gx,
                                                               uint32_t gy = 1, uint32_t gz = 1) const;

  private:
    Context& ctx_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    uint32_t push_bytes_ = 0;
    mutable bool warmed_ = false;
};

// Timestamp queries around passes. begin(name)/end() pairs in one command buffer; results after
// the submission completed.
//
// Each begin writes two bottom-of-pipe timestamps, the pass's and a marker after it. On lavapipe a
// timestamp waits in llvmpipe's rasterizer bins whenever a framebuffer has been bound (any earlier
// render pass in the process), and only a later non-top-of-pipe timestamp, which flushes, resolves
// it: without the marker a begin timestamp would resolve after the pass, and every compute pass
// timed after a draw read ~0 ms (measured: 0.01 ms for a 90 ms dispatch).
class GpuTimer {
  public:
    GpuTimer(Context& ctx, uint32_t max_passes);
    ~GpuTimer();
    void reset(VkCommandBuffer cmd);
    void begin(VkCommandBuffer cmd, const std::string& name);
    void end(VkCommandBuffer cmd);
    // Milliseconds per pass, in order, after the work has finished.
    std::vector<std::pair<std::string, double>> results() const;

  private:
    Context& ctx_;
    VkQueryPool pool_ = VK_NULL_HANDLE;
    uint32_t max_ = 0;
    std::vector<std::string> names_;
};

class Context {
  public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    const DeviceInfo& info() const { return info_; }
    VkDevice device() const { return device_; }
    VkPhysicalDevice physical_device() const { return physical_; }
    // Validation messages of severity error since creation (or the last reset).
    int validation_errors() const { return validation_errors_; }
    const std::vector<std::string>& validation_messages() const { return validation_messages_; }
    void reset_validation_errors() {
        validation_errors_ = 0;
        validation_messages_.clear();
    }

    Buffer create_buffer(VkDeviceSize size,
                         VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT |
                                                    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    // A 2D image or a cube (layers = 6), with `mips` levels, usable as storage + sampled + transfer.
    Image create_image(VkFormat format, uint32_t width, uint32_t height, uint32_t mips, bool cube);
    bool format_supports(VkFormat format, VkFormatFeatureFlags features) const;

    VkSampler linear_sampler() const { return linear_sampler_; }     // trilinear, clamp
    VkSampler equirect_sampler() const { return equirect_sampler_; } // bilinear, wrap u, clamp v
    VkSampler nearest_sampler() const { return nearest_sampler_; }

    // Records a one-shot command buffer, submits it and waits.
    template <class F> void submit(F&& record) {
        VkCommandBuffer cmd = begin_commands();
        record(cmd);
        end_and_wait(cmd);
    }
    VkCommandBuffer begin_commands();
    void end_and_wait(VkCommandBuffer cmd);

    // A global memory barrier: compute writes → compute/transfer reads (and layout transitions).
    static void barrier(VkCommandBuffer cmd);
    static void transition(VkCommandBuffer cmd, const Image& img, VkImageLayout from, VkImageLayout to);
    void copy_buffer_to_image(VkCommandBuffer cmd, const Buffer& src, const Image& dst, uint32_t mip = 0);
    // Reads one mip of an image (all layers) back as RGBA float, layer-major then row-major.
    // Supports RGBA32F, RGBA16F and RG16F (as R, G, 0, 1) images in the GENERAL layout (tests, debugging).
    std::vector<float> download(const Image& img, uint32_t mip);

    // Debug-utils callback entry (public for the C callback).
    void on_validation_message(int severity, const char* message);

    // Records vkCmdPushDescriptorSetKHR of `bindings` (set 0) for a pipeline of `bind_point`.
    void push_descriptors(VkCommandBuffer cmd, VkPipelineBindPoint bind_point, VkPipelineLayout layout,
                          const std::vector<Binding>& bindings) const;
    // A memory type with `props` among `bits` (VkMemoryRequirements::memoryTypeBits); EnvironmentError if none.
    uint32_t find_memory_type(uint32_t bits, VkMemoryPropertyFlags props) const;

  private:
    void create_pool_and_samplers();
    void destroy();

    DeviceInfo info_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    uint32_t queue_family_ = 0;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkSampler linear_sampler_ = VK_NULL_HANDLE, equirect_sampler_ = VK_NULL_HANDLE, nearest_sampler_ = VK_NULL_HANDLE;
    int validation_errors_ = 0;
    std::vector<std::string> validation_messages_;
    PFN_vkCmdPushDescriptorSetKHR push_descriptor_fn_ = nullptr;
};

// Throws EnvironmentError when VkResult is not VK_SUCCESS, naming the call.
void check(VkResult r, const char* what);

} // namespace iblcheck::vk
