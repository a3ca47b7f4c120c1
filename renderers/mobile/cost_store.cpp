#include "cost_store.h"

#include <cstring>

#include "kernel/cpu_caps.h"
#include "kernel/hash.h"
#include "kernel/store_entry.h"
#include "precompute_store.h"
#include "renderers/vulkan/shader_compiler.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {

constexpr char kMagic[] = "IBLCOST1"; // this layout; another is a miss

fs::path entry_path(const std::string& key) { return cost_store_dir() / (key + ".cost"); }

} // namespace

fs::path cost_store_dir() { return store_dir("IBLCHECK_COST_CACHE", vk::spirv_cache_dir().parent_path() / "cost"); }

std::string bytes_hash(const void* data, size_t n) {
    Fnv1a64 h;
    h.update(data, n);
    return h.hex() + ":" + std::to_string(n);
}

std::string shading_inputs_hash(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                                const vk::Buffer& scene_buf) {
    return precompute_store_key(gpu, env, s) + "/scene=" + bytes_hash(scene_buf.mapped, size_t(scene_buf.size));
}

std::string cost_store_key(GpuSession& gpu, const std::vector<std::string>& parts, const std::string& tool) {
    Fnv1a64 h;
    h.update("tool=" + tool + ";");
    h.update(std::string(kMagic) + ";");
    for (const std::string& p : parts) h.update(std::to_string(p.size()) + ":" + p + ";");
    const vk::DeviceInfo& i = gpu.ctx().info();
    h.update(i.device_name + ";" + i.driver_name + ";" + i.driver_info + ";" + i.api_version + ";");
    h.update(llvmpipe_caps().cpu_class());
    return h.hex();
}

std::optional<double> load_cost(const std::string& key) {
    if (cost_store_dir().empty()) return std::nullopt;
    // The magic, the key again (a renamed or misplaced file is a miss), the double's bits.
    const std::optional<std::string> bits = read_store_entry(entry_path(key), std::string(kMagic) + key);
    if (!bits || bits->size() != sizeof(double)) return std::nullopt;
    double v = 0;
    std::memcpy(&v, bits->data(), sizeof v);
    if (!(v >= 0)) return std::nullopt; // a count is finite and not negative
    return v;
}

void save_cost(const std::string& key, double instructions_per_pixel) {
    if (cost_store_dir().empty()) return;
    std::string bytes = std::string(kMagic) + key;
    bytes.append(reinterpret_cast<const char*>(&instructions_per_pixel), sizeof instructions_per_pixel);
    write_store_entry(entry_path(key), bytes);
}

} // namespace iblcheck
