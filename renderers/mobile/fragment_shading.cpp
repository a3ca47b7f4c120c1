#include "fragment_shading.h"

#include <cstring>

#include "cost_store.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "renderers/mobile/descriptor_types.h"
#include "renderers/mobile/gpu_scene.h"
#include "renderers/vulkan/spirv_cost.h"

namespace iblcheck {

namespace {
const std::vector<VkDescriptorType> kTypes = {kUniformBuffer, kSampled, kUniformBuffer, kSampled, kSampled};
constexpr uint32_t kQuadVertices = 4; // a triangle strip per sphere

// One draw of every sphere's impostor into `target`. With a timer, a one-pixel draw first makes
// llvmpipe build the fragment shader's variant outside the timed region (it compiles at the first
// draw, not at pipeline creation).
void record_draw(VkCommandBuffer cmd, const vk::GraphicsPipeline& p, const vk::OffscreenTarget& target,
                 const std::vector<vk::Binding>& bindings, const ShadePush& push, uint32_t spheres, vk::GpuTimer* timer) {
    if (timer) {
        target.begin(cmd, {0, 0, 0, 0});
        VkRect2D one_pixel{{0, 0}, {1, 1}};
        vkCmdSetScissor(cmd, 0, 1, &one_pixel);
        p.draw(cmd, bindings, &push, sizeof push, kQuadVertices, spheres);
        target.end(cmd);
        timer->begin(cmd, "shade_spheres_fragment");
    }
    target.begin(cmd, {0, 0, 0, 0});
    p.draw(cmd, bindings, &push, sizeof push, kQuadVertices, spheres);
    target.end(cmd);
    if (timer) timer->end(cmd);
}
// The store's key of the draw's count: its inputs, the counted modules' source hashes, the target and
// the timed draw's resolved image.
std::string fragment_cost_key(GpuSession& gpu, const FragmentShadingPass& pass, const ShadePush& push,
                              const vk::TargetFormat& format, const vk::CompileOptions& counting, const vk::Buffer& out) {
    return cost_store_key(
        gpu,
        {"fragment", pass.inputs_hash, vk::compile_shader("shade_spheres.vert", pass.defines, counting).source_hash,
         vk::compile_shader("shade_spheres.frag", pass.defines, counting).source_hash, bytes_hash(&push, sizeof push),
         std::to_string(pass.sphere_count),
         std::to_string(int(format.color)) + "/" + std::to_string(int(format.depth)) + "/" + std::to_string(int(format.samples)),
         bytes_hash(out.mapped, size_t(out.size))});
}

} // namespace

double box_downsample_rgba(const float* rgba, int width, int height, int ssaa, cv::Mat& rgb) {
    rgb.create(height, width, CV_32FC3);
    const int fw = width * ssaa;
    const double inv = 1.0 / double(ssaa * ssaa);
    double alpha = 0;
    for (int y = 0; y < height; ++y) {
        float* row = rgb.ptr<float>(y);
        for (int x = 0; x < width; ++x) {
            double sum[4] = {0, 0, 0, 0};
            for (int j = 0; j < ssaa; ++j)
                for (int i = 0; i < ssaa; ++i) {
                    const float* p = rgba + 4 * (size_t(y * ssaa + j) * size_t(fw) + size_t(x * ssaa + i));
                    for (int c = 0; c < 4; ++c) sum[c] += p[c];
                }
            for (int c = 0; c < 3; ++c) row[3 * x + c] = float(sum[c] * inv);
            alpha += sum[3] * inv;
        }
    }
    return alpha / (double(width) * height);
}

FragmentShadingResult shade_fragment(GpuSession& gpu, const FragmentShadingPass& pass) {
    vk::Context& ctx = gpu.ctx();
    const int ssaa = int(pass.push.ssaa);
    const int width = int(pass.push.width), height = int(pass.push.height);
    const uint32_t fw = uint32_t(width * ssaa), fh = uint32_t(height * ssaa);
    ShadePush push = pass.push;
    push.width = fw;
    push.height = fh;
    vk::TargetFormat format; // RGBA32F colour, D32 depth, 4 samples
    vk::require_target_support(ctx, format);

    const vk::GraphicsPipeline& pipeline = gpu.graphics_pipeline("shade_spheres.vert", "shade_spheres.frag", pass.defines, kTypes,
                                                                 sizeof push, format, pass.options);
    vk::OffscreenTarget target(ctx, fw, fh, format);
    vk::Buffer out = ctx.create_buffer(VkDeviceSize(fw) * fh * 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    vk::GpuTimer timer(ctx, 1);
    ctx.submit([&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        record_draw(cmd, pipeline, target, pass.bindings, push, pass.sphere_count, &timer);
        target.copy_resolved(cmd, out);
    });

    FragmentShadingResult r;
    for (auto& [name, ms] : timer.results()) r.timings.push_back({name, ms, true, false});
    const float* rgba = out.as<float>();
    r.non_finite_coverage = coverage_problem(rgba, int(fw), int(fh), ssaa, "shade_spheres.frag");
    r.coverage = box_downsample_rgba(rgba, width, height, ssaa, r.image);
    size_t shaded = 0;
    for (size_t i = 0; i < size_t(fw) * fh; ++i) shaded += rgba[4 * i + 3] > 0.0f;
    r.shaded_fragments_per_pixel = double(shaded) / (double(width) * height);

    // The cost: the instrumented twin draws again, untimed, into a target of its own; its image
    // must be the timed draw's bit for bit, or the count would describe another computation.
    if (ctx.info().int64_atomics && ctx.info().graphics_stores) {
        ProfileStage stage("counting_twin");
        vk::CompileOptions counting = pass.options;
        counting.count_instructions = true;
        const std::string key =
            pass.inputs_hash.empty() ? std::string() : fragment_cost_key(gpu, pass, push, format, counting, out);
        if (!key.empty())
            if (std::optional<double> stored = load_cost(key)) {
                r.instructions_per_pixel = stored;
                return r;
            }
        const vk::GraphicsPipeline& counted = gpu.graphics_pipeline("shade_spheres.vert", "shade_spheres.frag", pass.defines,
                                                                    kTypes, sizeof push, format, counting);
        vk::OffscreenTarget scratch_target(ctx, fw, fh, format);
        vk::Buffer scratch = ctx.create_buffer(out.size, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        vk::Buffer total = ctx.create_buffer(sizeof(uint64_t)); // zeroed at creation
        std::vector<vk::Binding> bindings = pass.bindings;
        bindings.push_back(vk::Binding::storage_buffer(vk::kCostBinding, total));
        ctx.submit([&](VkCommandBuffer cmd) {
            record_draw(cmd, counted, scratch_target, bindings, push, pass.sphere_count, nullptr);
            scratch_target.copy_resolved(cmd, scratch);
        });
        if (std::memcmp(scratch.mapped, out.mapped, size_t(out.size)) != 0)
            throw Error("shade_spheres.frag: the instruction-counting twin drew another image than the timed draw; "
                        "its count would not describe the frame");
        r.instructions_per_pixel = double(*total.as<uint64_t>()) / (double(width) * height);
        if (!key.empty()) save_cost(key, *r.instructions_per_pixel);
    }
    return r;
}

} // namespace iblcheck
