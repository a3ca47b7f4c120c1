// `--method sampled`: see shaders/shade_sampled.comp for the estimator. It shares the source
// pyramid and SH9 passes with the mobile pipeline and skips the prefiltered chain.
#include "sampled_renderer.h"

#include "kernel/errors.h"
#include "kernel/profile.h"
#include "renderers/mobile/cost_store.h"
#include "renderers/mobile/descriptor_types.h"
#include "renderers/mobile/gpu_scene.h"
#include "renderers/mobile/ibl_precompute.h"
#include "renderers/mobile/push_constants.h"
#include "renderers/mobile/shading_cost.h"
#include "renderers/option_table.h"

namespace iblcheck {

PrecomputeSettings sampled_precompute_settings(const TestSpec& spec) {
    PrecomputeSettings ps;
    ps.cube_size = uint32_t(option_int(spec.options, "cube_size", "sampled"));
    ps.prefiltered = false;
    ps.env_rotation_deg = float(option_double(spec.options, "env_rotation", "sampled"));
    return ps;
}

RenderResult render_sampled(GpuSession& gpu, const Environment& env, const TestSpec& spec) {
    const OptionMap& o = spec.options;
    int width = 0, height = 0;
    Scene scene = scene_for(spec, width, height);

    const PrecomputeSettings ps = sampled_precompute_settings(spec);
    int samples = option_int(o, "samples", "sampled");
    if (samples < 1 || samples > 65536) throw UsageError("option 'samples' must be in 1..65536");

    RenderResult result;
    bool cached = false;
    auto ibl_ptr = precompute_cached(gpu, env, ps, result.timings, cached);
    const IblResources& ibl = *ibl_ptr;
    const std::vector<VkDescriptorType> types = {kUniformBuffer, kSampled,       kUniformBuffer,
                                                 kUniformBuffer, kUniformBuffer, kStorageBuffer};
    const vk::Defines defines = glsl_defines(shader_selections(o, "sampled")); // mip_clamp
    ProfileStage stage("shading");
    const auto& shade = gpu.pipeline("shade_sampled.comp", defines, types, sizeof(SampledPush));
    vk::Context& ctx = gpu.ctx();
    vk::Buffer scene_buf = upload_scene(ctx, scene);
    vk::Buffer out = ctx.create_buffer(VkDeviceSize(width) * height * 16);
    SampledPush pc{uint32_t(width),
                   uint32_t(height),
                   uint32_t(option_int(o, "ssaa", "sampled")),
                   uint32_t(samples),
                   ps.cube_size,
                   uint32_t(option_int(o, "seed", "sampled")),
                   float(ibl.full_mips - 1),
                   float(option_double(o, "min_lod", "sampled")),
                   float(option_double(o, "diffuse_roughness", "sampled"))};
    if (pc.ssaa < 1 || pc.ssaa > 16) throw UsageError("option 'ssaa' must be in 1..16");

    // Bindings 3 and 4 are unused by this shader; the layout keeps the mobile numbering.
    std::vector<vk::Binding> b = {vk::Binding::uniform_buffer(0, scene_buf),
                                  vk::Binding::sampled_image(1, ibl.source_cube.sampled_view, ctx.linear_sampler()),
                                  vk::Binding::uniform_buffer(2, ibl.sh),
                                  vk::Binding::uniform_buffer(3, ibl.sh),
                                  vk::Binding::uniform_buffer(4, ibl.sh),
                                  vk::Binding::storage_buffer(5, out)};
    for (auto& [name, ms] : shade.dispatch_timed("shade_sampled", b, &pc, sizeof pc, (width + 7) / 8, (height + 7) / 8))
        result.timings.push_back({name, ms, true, false});
    double coverage = read_back_image(out, width, height, result.image, "shade_sampled.comp", result.non_finite_coverage);
    result.texture_fetches_per_pixel = coverage * pc.ssaa * pc.ssaa * samples;
    auto instructions = shading_instructions_per_pixel(gpu,
                                                       {"shade_sampled.comp",
                                                        defines,
                                                        types,
                                                        {},
                                                        b,
                                                        5,
                                                        &pc,
                                                        sizeof pc,
                                                        width,
                                                        height,
                                                        shading_inputs_hash(gpu, env, ps, scene_buf)},
                                                       out);
    result.shader_instructions_per_pixel = instructions.value_or(0);
    result.provenance = {{"method", "sampled"}, {"precompute_cached", cached},
                         {"samples", samples},  {"cube_size", ps.cube_size},
                         {"seed", pc.seed},     {"cost", cost_provenance(instructions, result.texture_fetches_per_pixel)}};
    return result;
}

} // namespace iblcheck
