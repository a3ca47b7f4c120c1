#include "mobile_renderer.h"

#include <chrono>
#include <optional>

#include "cost_store.h"
#include "fragment_shading.h"
#include "gpu_scene.h"
#include "ibl_precompute.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "mip_chain.h"
#include "renderers/mobile/descriptor_types.h"
#include "renderers/option_table.h"
#include "renderers/scenes/scene.h"
#include "renderers/vulkan/fp16_emulation.h"
#include "renderers/vulkan/shader_compiler.h"
#include "renderers/vulkan/spirv_texture_samples.h"
#include "shading_cost.h"

namespace iblcheck {

namespace {

// What a mobile render reads from its options before any GPU work, in the order it reads them
// (so the first invalid option is the one reported).
struct MobileOptions {
    PrecomputeSettings ps;
    std::map<std::string, std::string> variant; // the shader selections (option table)
    std::string fp16;
};

MobileOptions read_mobile_options(const OptionMap& o) {
    MobileOptions m;
    PrecomputeSettings& ps = m.ps;
    ps.cube_size = uint32_t(option_int(o, "cube_size", "mobile"));
    ps.mips = uint32_t(std::max(0, o.get_int("mips").value_or(0))); // 0: the full chain (the table's computed default)
    if (o.has("mips") && ps.mips < 1) throw UsageError("option 'mips' must be at least 1 (leave it out for the full chain)");
    ps.prefilter_samples = uint32_t(option_int(o, "prefilter_samples", "mobile"));
    m.variant = shader_selections(o, "mobile");
    ps.mip_mapping = m.variant.at("mip_mapping");
    ps.storage = m.variant.at("storage");
    ps.astc_block = option_choice(o, "astc_block");
    ps.env_layout = m.variant.at("env_layout");
    // rgbm_range: "peak" (default: the source's peak, ibl_precompute.cpp) or a fixed range.
    if (option_string(o, "rgbm_range", "mobile") != "peak") {
        ps.rgbm_range = float(o.get_double("rgbm_range").value()); // set: not the default
        if (!(ps.rgbm_range > 0)) throw UsageError("option 'rgbm_range' must be 'peak' or a number > 0");
    }
    ps.lut = m.variant.at("env_brdf") == "lut";
    ps.lut_size = uint32_t(option_int(o, "lut_size", "mobile"));
    ps.irradiance_cube = m.variant.at("diffuse") == "irradiance_cube";
    ps.env_rotation_deg = float(option_double(o, "env_rotation", "mobile"));
    if (ps.prefilter_samples < 1 || ps.prefilter_samples > 65536)
        throw UsageError("option 'prefilter_samples' must be in 1..65536");
    m.fp16 = option_choice(o, "fp16");
    return m;
}

// precision=mediump computes in float16_t: natively, or emulated where the device lacks
// shaderFloat16 (or fp16=emulated asks for it). One rule, shared with `iblcheck doctor`.
std::optional<vk::Fp16Path> fp16_path_of(GpuSession& gpu, const MobileOptions& m) {
    if (m.variant.at("precision") != "mediump") return std::nullopt;
    return vk::choose_fp16_path(m.fp16, gpu.ctx().info().shader_float16, gpu.ctx().info().device_name);
}

// The shading pass's defines: the storage's, the other selections', and per-sphere AO where the
// scene has it (scene.glsl).
vk::Defines shading_defines(const MobileOptions& m, const IblResources& ibl, const Scene& scene, bool contract) {
    vk::Defines defs = storage_defines(m.ps, ibl);
    defs.merge(glsl_defines(m.variant)); // keeps storage_defines' entries; adds the other selections
    if (scene_uses_ao(scene)) defs["MATERIAL_AO"] = "1";
    if (contract) defs["IBL_SHADE_CONTRACT"] = "1"; // a team's ibl_shade (ibl_contract.glsl)
    return defs;
}

// ssaa: rays per pixel (compute) or the supersampling factor (fragment, default 1: a phone
// renders at its resolution and relies on MSAA at silhouettes).
ShadePush shade_push(const OptionMap& o, int width, int height, const PrecomputeSettings& ps, const IblResources& ibl) {
    std::string indirect = option_string(o, "indirect_irradiance", "mobile");
    ShadePush pc{uint32_t(width),
                 uint32_t(height),
                 uint32_t(ssaa_of(o)),
                 float(cubemap_max_mip(ps.cube_size)),
                 float(ibl.levels - 1),
                 float(option_double(o, "mix_begin_roughness", "mobile")),
                 float(option_double(o, "mix_end_roughness", "mobile")),
                 float(option_double(o, "mix_largest_weight", "mobile")),
                 indirect == "sh9" ? -1.0f : float(o.get_double("indirect_irradiance").value()),
                 float(option_double(o, "specular_aa_variance", "mobile")),
                 float(option_double(o, "specular_aa_threshold", "mobile")),
                 ps.env_rotation_deg};
    if (pc.ssaa < 1 || pc.ssaa > 16) throw UsageError("option 'ssaa' must be in 1..16");
    if (pc.mix_end <= pc.mix_begin) throw UsageError("option 'mix_end_roughness' must exceed 'mix_begin_roughness'");
    return pc;
}

// Bindings 0..4 of both shading paths: the spheres, the prefiltered chain, SH9, the LUT and the
// irradiance cube (compute adds its output image at 5).
std::vector<vk::Binding> shading_bindings(vk::Context& ctx, const vk::Buffer& scene_buf, const IblResources& ibl) {
    return {vk::Binding::uniform_buffer(0, scene_buf),
            vk::Binding::sampled_image(1, ibl.prefiltered.sampled_view, ctx.linear_sampler()),
            vk::Binding::uniform_buffer(2, ibl.sh), vk::Binding::sampled_image(3, ibl.lut.sampled_view, ctx.linear_sampler()),
            vk::Binding::sampled_image(4, ibl.irradiance.sampled_view, ctx.linear_sampler())};
}

// Texture samples per shading: one prefiltered-cube read (two for a 2D layout, one per level:
// env_layout.glsl; a second read at n for normalization=directional), plus the LUT and the
// irradiance cube when used (SH9 is arithmetic).
double texture_samples_per_hit(const MobileOptions& m) {
    const double env_reads =
        (m.variant.at("normalization") == "directional" ? 2.0 : 1.0) * (m.ps.env_layout == "cube" ? 1.0 : 2.0);
    return env_reads + (m.ps.lut ? 1.0 : 0.0) + (m.ps.irradiance_cube ? 1.0 : 0.0);
}

// A team's shading (docs/SHADER_CONTRACT.md) does its own lookups: its texture samples per shading
// are read from its SPIR-V (spirv_texture_samples.h), the module already compiled for the pass.
double contract_samples_per_hit(const vk::Defines& defines, const vk::CompileOptions& options, bool fragment) {
    const vk::CompiledShader module =
        vk::compile_shader(fragment ? "shade_spheres.frag" : "shade_spheres.comp", defines, options);
    return vk::image_samples_per_call(module.spirv, "ibl_shade(");
}

// What both shading paths draw with.
struct ShadingInputs {
    vk::Defines defines;
    vk::CompileOptions options; // fp16 emulation
    std::vector<vk::Binding> bindings;
    ShadePush push;
    uint32_t sphere_count;
    double per_hit;          // texture samples per shading
    std::string inputs_hash; // of the precompute and the scene: the stored count's key (cost_store.h)
};

// shading=fragment into `result` (image, timings, texture fetches); returns its instruction count.
std::optional<double> shade_with_fragments(GpuSession& gpu, const ShadingInputs& in, RenderResult& result) {
    ProfileStage stage("shading");
    FragmentShadingResult f =
        shade_fragment(gpu, {in.defines, in.options, in.bindings, in.push, in.sphere_count, in.inputs_hash});
    result.image = f.image;
    result.non_finite_coverage = f.non_finite_coverage;
    result.timings.insert(result.timings.end(), f.timings.begin(), f.timings.end());
    result.texture_fetches_per_pixel = f.shaded_fragments_per_pixel * in.per_hit;
    return f.instructions_per_pixel;
}

// shading=compute into `result` (image, timings, texture fetches); returns its instruction count.
std::optional<double> shade_with_compute(GpuSession& gpu, const ShadingInputs& in, RenderResult& result) {
    ProfileStage stage("shading");
    vk::Context& ctx = gpu.ctx();
    const int width = int(in.push.width), height = int(in.push.height);
    const std::vector<VkDescriptorType> types = {kUniformBuffer, kSampled, kUniformBuffer, kSampled, kSampled, kStorageBuffer};
    const auto& shade = gpu.pipeline("shade_spheres.comp", in.defines, types, sizeof(ShadePush), in.options);
    vk::Buffer out = ctx.create_buffer(VkDeviceSize(width) * height * 16);
    std::vector<vk::Binding> b = in.bindings;
    b.push_back(vk::Binding::storage_buffer(5, out));
    const ShadePush& pc = in.push;
    for (auto& [name, ms] : shade.dispatch_timed("shade_spheres", b, &pc, sizeof pc, (width + 7) / 8, (height + 7) / 8))
        result.timings.push_back({name, ms, true, false});
    double coverage = read_back_image(out, width, height, result.image, "shade_spheres.comp", result.non_finite_coverage);
    // One shading per ray that hits.
    result.texture_fetches_per_pixel = coverage * pc.ssaa * pc.ssaa * in.per_hit;
    return shading_instructions_per_pixel(
        gpu, {"shade_spheres.comp", in.defines, types, in.options, b, 5, &pc, sizeof pc, width, height, in.inputs_hash}, out);
}

nlohmann::json mobile_provenance(const MobileOptions& m, const IblResources& ibl, bool cached, std::optional<double> instructions,
                                 double texture_fetches_per_pixel) {
    const PrecomputeSettings& ps = m.ps;
    return {{"method", "mobile"},
            {"cost", cost_provenance(instructions, texture_fetches_per_pixel)},
            {"precompute_cached", cached},
            {"cube_size", ps.cube_size},
            {"mips", ibl.levels},
            {"storage_native", ps.storage != "r11g11b10" || ibl.native_r11g11b10},
            {"rgbm", ibl.rgbm_range > 0 ? nlohmann::json{{"range", ibl.rgbm_range},
                                                         {"range_from", ps.rgbm_range > 0 ? "option" : "peak"},
                                                         {"clipped_energy", ibl.rgbm_clipped_energy}}
                                        : nlohmann::json()},
            {"texture", {{"layout", ps.env_layout}, {"texels", ibl.texel_count}, {"bytes", ibl.texture_bytes}}},
            {"shader_variant", glsl_selection_names(m.variant)}};
}

// What the cost counts differs from compute's: renderers/mobile/fragment_shading.h.
nlohmann::json fragment_provenance(const ShadingInputs& in, double texture_fetches_per_pixel) {
    return {{"msaa_samples", 4},
            {"ssaa", in.push.ssaa},
            {"shaded_fragments_per_pixel", texture_fetches_per_pixel / in.per_hit},
            {"instructions_counted", "vertex and fragment invocations; helper invocations excluded"}};
}

} // namespace

PrecomputeSettings mobile_precompute_settings(const TestSpec& spec) {
    PrecomputeSettings ps = read_mobile_options(spec.options).ps;
    if (!spec.shader.empty()) ps.lut = true; // as render_mobile: the contract always binds the DFG LUT
    return ps;
}

RenderResult render_mobile(GpuSession& gpu, const Environment& env, const TestSpec& spec) {
    const OptionMap& o = spec.options;
    int width = 0, height = 0;
    Scene scene = scene_for(spec, width, height);
    MobileOptions m = read_mobile_options(o);
    const bool contract = !spec.shader.empty();
    if (contract) {
        vk::check_ibl_shade_file(spec.shader); // before any GPU work: a missing file is exit 2
        m.ps.lut = true;                       // the contract always binds the DFG LUT
    }
    const std::optional<vk::Fp16Path> fp16_path = fp16_path_of(gpu, m);

    RenderResult result;
    bool cached = false;
    auto ibl_ptr = precompute_cached(gpu, env, m.ps, result.timings, cached);
    const IblResources& ibl = *ibl_ptr;

    ShadingInputs in;
    in.defines = shading_defines(m, ibl, scene, contract);
    in.options.emulate_fp16 = fp16_path == vk::Fp16Path::emulated;
    if (contract) in.options.ibl_shade = spec.shader;
    vk::Context& ctx = gpu.ctx();
    vk::Buffer scene_buf = upload_scene(ctx, scene);
    in.push = shade_push(o, width, height, m.ps, ibl);
    in.bindings = shading_bindings(ctx, scene_buf, ibl);
    in.sphere_count = uint32_t(scene.spheres.size());
    in.inputs_hash = shading_inputs_hash(gpu, env, m.ps, scene_buf);
    const bool fragment = m.variant.at("shading") == "fragment";
    in.per_hit = contract ? contract_samples_per_hit(in.defines, in.options, fragment) : texture_samples_per_hit(m);

    std::optional<double> instructions = fragment ? shade_with_fragments(gpu, in, result) : shade_with_compute(gpu, in, result);
    result.shader_instructions_per_pixel = instructions.value_or(0);
    result.texel_count = ibl.texel_count;
    result.texture_bytes = ibl.texture_bytes;
    result.provenance = mobile_provenance(m, ibl, cached, instructions, result.texture_fetches_per_pixel);
    if (fp16_path) result.provenance["fp16"] = vk::fp16_path_name(*fp16_path);
    if (fragment) result.provenance["fragment"] = fragment_provenance(in, result.texture_fetches_per_pixel);
    if (contract)
        result.provenance["ibl_shade"] = {{"file", std::filesystem::path(spec.shader).filename().string()},
                                          {"hash", vk::ibl_shade_hash(spec.shader)},
                                          {"texture_samples_per_shading", in.per_hit}};
    return result;
}

} // namespace iblcheck
