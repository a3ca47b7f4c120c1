#include "mobile_renderer.h"

#include <chrono>
#include <optional>

#include "fragment_shading.h"
#include "gpu_scene.h"
#include "harness/common/errors.h"
#include "ibl_precompute.h"
#include "renderers/mobile/descriptor_types.h"
#include "renderers/option_table.h"
#include "renderers/scenes/scene.h"
#include "renderers/vulkan/fp16_emulation.h"
#include "shading_cost.h"

namespace iblcheck {

RenderResult render_mobile(GpuSession& gpu, const Environment& env, const TestSpec& spec) {
    const OptionMap& o = spec.options;
    int width = 0, height = 0;
    Scene scene = scene_for(spec, width, height);

    PrecomputeSettings ps;
    ps.cube_size = uint32_t(o.get_int("cube_size", 128));
    ps.mips = uint32_t(o.get_int("mips", 7));
    ps.prefilter_samples = uint32_t(o.get_int("prefilter_samples", 64));
    const std::map<std::string, std::string> variant = shader_selections(o, "mobile");
    ps.mip_mapping = variant.at("mip_mapping");
    ps.storage = variant.at("storage");
    ps.astc_block = option_choice(o, "astc_block");
    ps.env_layout = variant.at("env_layout");
    ps.rgbm_range = float(o.get_double("rgbm_range", 6.0));
    ps.lut = variant.at("env_brdf") == "lut";
    ps.lut_size = uint32_t(o.get_int("lut_size", 64));
    ps.irradiance_cube = variant.at("diffuse") == "irradiance_cube";
    ps.env_rotation_deg = float(o.get_double("env_rotation", 0.0));
    if (ps.prefilter_samples < 1 || ps.prefilter_samples > 65536)
        throw UsageError("option 'prefilter_samples' must be in 1..65536");
    std::string fp16 = option_choice(o, "fp16");
    // precision=mediump computes in float16_t: natively, or emulated where the device lacks
    // shaderFloat16 (or fp16=emulated asks for it). One rule, shared with `iblcheck doctor`.
    std::optional<vk::Fp16Path> fp16_path;
    if (variant.at("precision") == "mediump")
        fp16_path = vk::choose_fp16_path(fp16, gpu.ctx().info().shader_float16, gpu.ctx().info().device_name);
    vk::CompileOptions shade_options;
    shade_options.emulate_fp16 = fp16_path == vk::Fp16Path::emulated;

    RenderResult result;
    bool cached = false;
    auto ibl_ptr = precompute_cached(gpu, env, ps, result.timings, cached);
    const IblResources& ibl = *ibl_ptr;

    vk::Defines defs = storage_defines(ps, ibl.native_r11g11b10);
    defs.merge(glsl_defines(variant)); // keeps storage_defines' entries; adds the other selections
    const bool fragment = variant.at("shading") == "fragment";
    if (scene_uses_ao(scene)) defs["MATERIAL_AO"] = "1"; // scene.glsl: each sphere carries its AO

    vk::Context& ctx = gpu.ctx();
    vk::Buffer scene_buf = upload_scene(ctx, scene);
    std::string indirect = o.get_string("indirect_irradiance", "sh9");
    // ssaa: rays per pixel (compute) or the supersampling factor (fragment, default 1: a phone
    // renders at its resolution and relies on MSAA at silhouettes).
    ShadePush pc{uint32_t(width),
                 uint32_t(height),
                 uint32_t(ssaa_of(o)),
                 float(ibl.full_mips),
                 float(std::min(ps.mips, ibl.full_mips) - 1),
                 float(o.get_double("mix_begin_roughness", 0.1)),
                 float(o.get_double("mix_end_roughness", 0.3)),
                 float(o.get_double("mix_largest_weight", 10000.0)),
                 indirect == "sh9" ? -1.0f : float(o.get_double("indirect_irradiance", 0)),
                 float(o.get_double("specular_aa_variance", 0.25)),
                 float(o.get_double("specular_aa_threshold", 0.18)),
                 ps.env_rotation_deg};
    if (pc.ssaa < 1 || pc.ssaa > 16) throw UsageError("option 'ssaa' must be in 1..16");
    if (pc.mix_end <= pc.mix_begin) throw UsageError("option 'mix_end_roughness' must exceed 'mix_begin_roughness'");

    std::vector<vk::Binding> b = {vk::Binding::storage_buffer(0, scene_buf),
                                  vk::Binding::sampled_image(1, ibl.prefiltered.sampled_view, ctx.linear_sampler()),
                                  vk::Binding::storage_buffer(2, ibl.sh),
                                  vk::Binding::sampled_image(3, ibl.lut.sampled_view, ctx.linear_sampler()),
                                  vk::Binding::sampled_image(4, ibl.irradiance.sampled_view, ctx.linear_sampler())};
    // Texture samples per shading: one prefiltered-cube read (two for a 2D layout, one per level:
    // env_layout.glsl; a second read at n for normalization=directional), plus the LUT and the
    // irradiance cube when used (SH9 is arithmetic).
    const double env_reads = (variant.at("normalization") == "directional" ? 2.0 : 1.0) * (ps.env_layout == "cube" ? 1.0 : 2.0);
    const double per_hit = env_reads + (ps.lut ? 1.0 : 0.0) + (ps.irradiance_cube ? 1.0 : 0.0);
    std::optional<double> instructions;
    if (fragment) {
        FragmentShadingResult f = shade_fragment(gpu, {defs, shade_options, b, pc, uint32_t(scene.spheres.size())});
        result.image = f.image;
        result.timings.insert(result.timings.end(), f.timings.begin(), f.timings.end());
        result.texture_fetches_per_pixel = f.shaded_fragments_per_pixel * per_hit;
        instructions = f.instructions_per_pixel;
    } else {
        const std::vector<VkDescriptorType> types = {kStorageBuffer, kSampled, kStorageBuffer,
                                                     kSampled,       kSampled, kStorageBuffer};
        const auto& shade = gpu.pipeline("shade_spheres.comp", defs, types, sizeof(ShadePush), shade_options);
        vk::Buffer out = ctx.create_buffer(VkDeviceSize(width) * height * 16);
        b.push_back(vk::Binding::storage_buffer(5, out));
        vk::GpuTimer timer(ctx, 1);
        ctx.submit([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            shade.warm_up(cmd, b, &pc, sizeof pc);
            timer.begin(cmd, "shade_spheres");
            shade.dispatch(cmd, b, &pc, sizeof pc, (width + 7) / 8, (height + 7) / 8, 1);
            timer.end(cmd);
            ctx.barrier(cmd);
        });
        for (auto& [name, ms] : timer.results()) result.timings.push_back({name, ms, true, false});
        double coverage = read_back_image(out, width, height, result.image);
        // One shading per ray that hits.
        result.texture_fetches_per_pixel = coverage * pc.ssaa * pc.ssaa * per_hit;
        instructions = shading_instructions_per_pixel(
            gpu, {"shade_spheres.comp", defs, types, shade_options, b, 5, &pc, sizeof pc, width, height}, out);
    }
    result.shader_instructions_per_pixel = instructions.value_or(0);
    result.texel_count = ibl.texel_count;
    result.texture_bytes = ibl.texture_bytes;
    result.provenance = {{"method", "mobile"},
                         {"cost", cost_provenance(instructions, result.texture_fetches_per_pixel)},
                         {"precompute_cached", cached},
                         {"cube_size", ps.cube_size},
                         {"mips", std::min(ps.mips, ibl.full_mips)},
                         {"storage_native", ps.storage != "r11g11b10" || ibl.native_r11g11b10},
                         {"texture", {{"layout", ps.env_layout}, {"texels", ibl.texel_count}, {"bytes", ibl.texture_bytes}}},
                         {"shader_variant", glsl_selection_names(variant)}};
    if (fp16_path) result.provenance["fp16"] = vk::fp16_path_name(*fp16_path);
    if (fragment) {
        // What the cost counts differs from compute's: renderers/mobile/fragment_shading.h.
        result.provenance["fragment"] = {
            {"msaa_samples", 4},
            {"ssaa", pc.ssaa},
            {"shaded_fragments_per_pixel", result.texture_fetches_per_pixel / per_hit},
            {"instructions_counted", "vertex and fragment invocations; helper invocations excluded"}};
    }
    return result;
}

} // namespace iblcheck
