#include "mobile_renderer.h"

#include <chrono>
#include <optional>

#include "gpu_scene.h"
#include "harness/common/errors.h"
#include "ibl_precompute.h"
#include "renderers/scenes/scene.h"
#include "shading_cost.h"
#include "renderers/vulkan/fp16_emulation.h"

namespace iblcheck {

namespace {
constexpr VkDescriptorType kSampled = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
constexpr VkDescriptorType kStorageBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;

std::string index_of(const std::string& key, const std::string& value, const std::vector<std::string>& names) {
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == value) return std::to_string(i);
    throw UsageError("option '" + key + "': unknown value '" + value + "'");
}
} // namespace

RenderResult render_mobile(GpuSession& gpu, const Environment& env, const TestSpec& spec) {
    const OptionMap& o = spec.options;
    int width = 0, height = 0;
    Scene scene = scene_for(spec, width, height);

    PrecomputeSettings ps;
    ps.cube_size = uint32_t(o.get_int("cube_size", 128));
    ps.mips = uint32_t(o.get_int("mips", 7));
    ps.prefilter_samples = uint32_t(o.get_int("prefilter_samples", 64));
    ps.mip_mapping = o.get_choice("mip_mapping", "ue4", {"ue4", "filament", "origin"});
    ps.storage = o.get_choice("storage", "rgba16f", {"rgba16f", "rgba32f", "rgbm8", "r11g11b10"});
    ps.rgbm_range = float(o.get_double("rgbm_range", 6.0));
    std::string env_brdf = o.get_choice("env_brdf", "approx", {"approx", "lut"});
    std::string diffuse = o.get_choice("diffuse", "sh9", {"sh9", "irradiance_cube"});
    ps.lut = env_brdf == "lut";
    ps.lut_size = uint32_t(o.get_int("lut_size", 64));
    ps.irradiance_cube = diffuse == "irradiance_cube";
    ps.env_rotation_deg = float(o.get_double("env_rotation", 0.0));
    std::string precision = o.get_choice("precision", "highp", {"highp", "mediump"});
    std::string dominant = o.get_choice("dominant_dir", "off", {"off", "lagarde", "filament"});
    std::string normalization = o.get_choice("normalization", "off", {"off", "ue4"});
    std::string spec_aa = o.get_choice("specular_aa", "off", {"off", "tokuyoshi", "rjump", "toksvig"});
    if (ps.prefilter_samples < 1 || ps.prefilter_samples > 65536)
        throw UsageError("option 'prefilter_samples' must be in 1..65536");
    std::string fp16 = o.get_choice("fp16", "auto", {"auto", "native", "emulated"});
    // precision=mediump computes in float16_t: natively, or emulated where the device lacks
    // shaderFloat16 (or fp16=emulated asks for it). One rule, shared with `iblcheck doctor`.
    std::optional<vk::Fp16Path> fp16_path;
    if (precision == "mediump")
        fp16_path = vk::choose_fp16_path(fp16, gpu.ctx().info().shader_float16, gpu.ctx().info().device_name);
    vk::CompileOptions shade_options;
    shade_options.emulate_fp16 = fp16_path == vk::Fp16Path::emulated;

    RenderResult result;
    bool cached = false;
    auto ibl_ptr = precompute_cached(gpu, env, ps, result.timings, cached);
    const IblResources& ibl = *ibl_ptr;

    vk::Defines defs = storage_defines(ps, ibl.native_r11g11b10);
    defs["MIP_MAPPING"] = mip_mapping_define(ps.mip_mapping);
    defs["ENV_BRDF"] = index_of("env_brdf", env_brdf, {"approx", "lut"});
    defs["DIFFUSE"] = index_of("diffuse", diffuse, {"sh9", "irradiance_cube"});
    defs["DOMINANT_DIR"] = index_of("dominant_dir", dominant, {"off", "lagarde", "filament"});
    defs["NORMALIZATION"] = index_of("normalization", normalization, {"off", "ue4"});
    defs["PRECISION_MEDIUMP"] = precision == "mediump" ? "1" : "0";
    defs["SPECULAR_AA"] = index_of("specular_aa", spec_aa, {"off", "tokuyoshi", "rjump", "toksvig"});
    const std::vector<VkDescriptorType> types = {kStorageBuffer, kSampled, kStorageBuffer, kSampled, kSampled, kStorageBuffer};
    const auto& shade = gpu.pipeline("shade_spheres.comp", defs, types, 48, shade_options);

    vk::Context& ctx = gpu.ctx();
    vk::Buffer scene_buf = upload_scene(ctx, scene);
    vk::Buffer out = ctx.create_buffer(VkDeviceSize(width) * height * 16);
    std::string indirect = o.get_string("indirect_irradiance", "sh9");
    struct {
        uint32_t width, height, ssaa;
        float full_mips, max_lod, mix_begin, mix_end, mix_largest, indirect, aa_variance, aa_threshold, rot;
    } pc{uint32_t(width),
         uint32_t(height),
         uint32_t(o.get_int("ssaa", 2)),
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
                                  vk::Binding::sampled_image(4, ibl.irradiance.sampled_view, ctx.linear_sampler()),
                                  vk::Binding::storage_buffer(5, out)};
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
    // Texture samples per pixel: one prefiltered-cube read per ray that hits, plus the LUT and the
    // irradiance cube when used (SH9 is arithmetic).
    double per_hit = 1.0 + (ps.lut ? 1.0 : 0.0) + (ps.irradiance_cube ? 1.0 : 0.0);
    result.texture_fetches_per_pixel = coverage * pc.ssaa * pc.ssaa * per_hit;
    auto instructions = shading_instructions_per_pixel(gpu, {"shade_spheres.comp", defs, types, shade_options, b, 5, &pc, sizeof pc, width, height}, out);
    result.shader_instructions_per_pixel = instructions.value_or(0);
    result.provenance = {{"method", "mobile"},
                         {"cost", cost_provenance(instructions, result.texture_fetches_per_pixel)},
                         {"precompute_cached", cached},
                         {"cube_size", ps.cube_size},
                         {"mips", std::min(ps.mips, ibl.full_mips)},
                         {"storage_native", ps.storage != "r11g11b10" || ibl.native_r11g11b10},
                         {"shader_defines", defs}};
    if (fp16_path) result.provenance["fp16"] = vk::fp16_path_name(*fp16_path);
    return result;
}

} // namespace iblcheck
