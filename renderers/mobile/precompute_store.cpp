#include "precompute_store.h"

#include <cstring>

#include "kernel/cpu_caps.h"
#include "kernel/hash.h"
#include "kernel/profile.h"
#include "kernel/store_entry.h"
#include "renderers/vulkan/shader_compiler.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {

constexpr uint32_t kPrecomputeMagic = 0x31434249; // "IBC1": this layout; another is a miss
constexpr uint32_t kEndMark = 0x444e4549;

// The shaders the passes compile (ibl_precompute.cpp); their includes are hashed with them.
const char* const kPassShaders[] = {"equirect_to_cube.comp", "downsample_cube.comp", "prefilter_ggx.comp", "sh9_project.comp",
                                    "dfg_lut.comp",          "irradiance_cube.comp", "encode_storage.comp"};

size_t texel_bytes(VkFormat f) {
    switch (f) {
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    case VK_FORMAT_R16G16B16A16_SFLOAT: return 8;
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32: return 4;
    default: return 0;
    }
}

size_t level_bytes(const vk::Image& img, uint32_t mip) {
    return size_t(std::max(1u, img.width >> mip)) * std::max(1u, img.height >> mip) * img.layers * texel_bytes(img.format);
}

// One mip of `img` (all layers) as the bytes the device holds.
std::string read_level(vk::Context& ctx, const vk::Image& img, uint32_t mip) {
    vk::Buffer buf = ctx.create_buffer(level_bytes(img, mip), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    ctx.submit([&](VkCommandBuffer cmd) {
        vk::Context::barrier(cmd);
        VkBufferImageCopy r{};
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, img.layers};
        r.imageExtent = {std::max(1u, img.width >> mip), std::max(1u, img.height >> mip), 1};
        vkCmdCopyImageToBuffer(cmd, img.image, VK_IMAGE_LAYOUT_GENERAL, buf.buffer, 1, &r);
        vk::Context::barrier(cmd);
    });
    return std::string(static_cast<const char*>(buf.mapped), level_bytes(img, mip));
}

struct Writer {
    std::string bytes;
    template <class T> void put(const T& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); }
    void put_string(const std::string& s) {
        put(uint64_t(s.size()));
        bytes += s;
    }
};

struct Reader {
    const std::string& bytes;
    size_t at = 0;
    template <class T> bool get(T& v) {
        if (at + sizeof v > bytes.size()) return false;
        std::memcpy(&v, bytes.data() + at, sizeof v);
        at += sizeof v;
        return true;
    }
    bool get_string(std::string& s) {
        uint64_t n = 0;
        if (!get(n) || n > bytes.size() - at) return false;
        s.assign(bytes, at, n);
        at += n;
        return true;
    }
};

void put_image(vk::Context& ctx, Writer& w, const vk::Image& img) {
    w.put(uint32_t(img.format));
    w.put(img.width);
    w.put(img.height);
    w.put(img.mips);
    w.put(uint8_t(img.cube));
    for (uint32_t m = 0; m < img.mips; ++m) w.put_string(read_level(ctx, img, m));
}

// An image as put_image wrote it, uploaded into a new one left in the GENERAL layout (as the passes
// leave theirs); false on a malformed entry.
bool get_image(vk::Context& ctx, Reader& rd, vk::Image& out) {
    uint32_t format = 0, width = 0, height = 0, mips = 0;
    uint8_t cube = 0;
    if (!rd.get(format) || !rd.get(width) || !rd.get(height) || !rd.get(mips) || !rd.get(cube)) return false;
    if (!texel_bytes(VkFormat(format)) || width == 0 || height == 0 || mips == 0 || mips > 16) return false;
    out = ctx.create_image(VkFormat(format), width, height, mips, cube != 0);
    std::vector<vk::Buffer> staging;
    for (uint32_t m = 0; m < mips; ++m) {
        std::string level;
        if (!rd.get_string(level) || level.size() != level_bytes(out, m)) return false;
        staging.push_back(ctx.create_buffer(level.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT));
        std::memcpy(staging.back().mapped, level.data(), level.size());
    }
    ctx.submit([&](VkCommandBuffer cmd) {
        vk::Context::transition(cmd, out, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        for (uint32_t m = 0; m < mips; ++m) ctx.copy_buffer_to_image(cmd, staging[m], out, m);
        vk::Context::transition(cmd, out, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
    });
    return true;
}

fs::path precompute_entry_path(const std::string& key) { return precompute_store_dir() / (key + ".ibl"); }

} // namespace

fs::path precompute_store_dir() {
    return store_dir("IBLCHECK_PRECOMPUTE_CACHE", vk::spirv_cache_dir().parent_path() / "precompute");
}

std::string precompute_store_key(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s, const std::string& tool) {
    Fnv1a64 h;
    h.update("tool=" + tool + ";");
    h.update(std::to_string(kPrecomputeMagic) + ";" + precompute_key(env.content_hash, s) + ";");
    for (const char* shader : kPassShaders)
        h.update(std::string(shader) + "=" + vk::file_tree_hash(vk::shader_dir() / shader) + ";");
    const vk::DeviceInfo& i = gpu.ctx().info();
    h.update(i.device_name + ";" + i.driver_name + ";" + i.driver_info + ";" + i.api_version + ";");
    h.update(llvmpipe_caps().cpu_class());
    return h.hex();
}

std::optional<IblResources> load_precompute(vk::Context& ctx, const std::string& key, std::vector<PassTiming>& timings) {
    if (precompute_store_dir().empty()) return std::nullopt;
    ProfileStage stage("precompute_store");
    const std::optional<std::string> entry = read_store_entry(precompute_entry_path(key), {}); // the magic is read below
    if (!entry) return std::nullopt;
    const std::string& bytes = *entry;
    Reader rd{bytes};
    uint32_t magic = 0, end = 0, n_timings = 0;
    uint8_t native = 0;
    IblResources r;
    if (!rd.get(magic) || magic != kPrecomputeMagic || !rd.get(r.full_mips) || !rd.get(r.levels) || !rd.get(native) ||
        !rd.get(r.texel_count) || !rd.get(r.texture_bytes) || !rd.get(r.rgbm_range) || !rd.get(r.rgbm_clipped_energy) ||
        !rd.get(n_timings) || n_timings > 64)
        return std::nullopt;
    r.native_r11g11b10 = native != 0;
    std::vector<PassTiming> stored(n_timings);
    for (PassTiming& t : stored) {
        uint8_t gpu = 0, pre = 0;
        if (!rd.get_string(t.name) || !rd.get(t.ms) || !rd.get(gpu) || !rd.get(pre)) return std::nullopt;
        t.gpu = gpu != 0;
        t.precompute = pre != 0;
    }
    std::string sh;
    if (!get_image(ctx, rd, r.source_cube) || !get_image(ctx, rd, r.prefiltered) || !rd.get_string(sh) || sh.size() != 160 ||
        !get_image(ctx, rd, r.lut) || !get_image(ctx, rd, r.irradiance) || !rd.get(end) || end != kEndMark ||
        rd.at != bytes.size())
        return std::nullopt;
    r.sh = ctx.create_buffer(sh.size());
    std::memcpy(r.sh.mapped, sh.data(), sh.size());
    timings.insert(timings.end(), stored.begin(), stored.end());
    return r;
}

void save_precompute(vk::Context& ctx, const std::string& key, const IblResources& r, const std::vector<PassTiming>& timings) {
    if (precompute_store_dir().empty()) return;
    ProfileStage stage("precompute_store");
    Writer w;
    w.put(kPrecomputeMagic);
    w.put(r.full_mips);
    w.put(r.levels);
    w.put(uint8_t(r.native_r11g11b10));
    w.put(r.texel_count);
    w.put(r.texture_bytes);
    w.put(r.rgbm_range);
    w.put(r.rgbm_clipped_energy);
    w.put(uint32_t(timings.size()));
    for (const PassTiming& t : timings) {
        w.put_string(t.name);
        w.put(t.ms);
        w.put(uint8_t(t.gpu));
        w.put(uint8_t(t.precompute));
    }
    put_image(ctx, w, r.source_cube);
    put_image(ctx, w, r.prefiltered);
    w.put_string(std::string(static_cast<const char*>(r.sh.mapped), size_t(r.sh.size)));
    put_image(ctx, w, r.lut);
    put_image(ctx, w, r.irradiance);
    w.put(kEndMark);
    write_store_entry(precompute_entry_path(key), w.bytes);
}

} // namespace iblcheck
