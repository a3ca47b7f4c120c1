// The Context's buffers and images (creation, moves, release), one-shot command buffers, barriers
// and layout transitions, uploads and read-backs.
#include <cstring>

#include "context.h"
#include "half_float.h"
#include "kernel/errors.h"
#include "vk_struct.h"

namespace iblcheck::vk {

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
    ai.memoryTypeIndex =
        find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
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
    mb.dstAccessMask =
        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &mb, 0, nullptr, 0, nullptr);
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
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
}

void Context::copy_buffer_to_image(VkCommandBuffer cmd, const Buffer& src, const Image& dst, uint32_t mip) {
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, dst.layers};
    r.imageExtent = {std::max(1u, dst.width >> mip), std::max(1u, dst.height >> mip), 1};
    vkCmdCopyBufferToImage(cmd, src.buffer, dst.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
}

std::vector<float> Context::download(const Image& img, uint32_t mip) {
    uint32_t w = std::max(1u, img.width >> mip), h = std::max(1u, img.height >> mip);
    size_t texels = size_t(w) * h * img.layers;
    size_t bpp = img.format == VK_FORMAT_R32G32B32A32_SFLOAT   ? 16
                 : img.format == VK_FORMAT_R16G16B16A16_SFLOAT ? 8
                 : img.format == VK_FORMAT_R16G16_SFLOAT       ? 4
                                                               : 0;
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
                for (int c = 0; c < 4; ++c) out[4 * i + c] = half_bits_to_float(hp[4 * i + c]);
            else {
                out[4 * i] = half_bits_to_float(hp[2 * i]);
                out[4 * i + 1] = half_bits_to_float(hp[2 * i + 1]);
                out[4 * i + 2] = 0;
                out[4 * i + 3] = 1;
            }
        }
    }
    return out;
}

} // namespace iblcheck::vk
