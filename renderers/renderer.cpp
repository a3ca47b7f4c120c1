#include "renderer.h"

#include <chrono>
#include <set>

#include "harness/common/errors.h"
#include "renderers/environments/environment.h"
#include "renderers/mobile/gpu_session.h"
#include "renderers/mobile/mobile_renderer.h"
#include "renderers/reference/reference.h"
#include "renderers/scenes/scene.h"
#include "renderers/vulkan/shader_compiler.h"

namespace iblcheck {

std::vector<MethodInfo> method_catalog() {
    return {
        {"mobile", "the split-sum pipeline under test (Vulkan): prefiltered GGX chain, SH9, EnvBRDF"},
        {"sampled", "per-pixel GGX importance sampling with filtered lookups (Substance Painter's approach, Vulkan)"},
        {"reference", "CPU ground truth: deterministic quadrature of the full BRDF against the full-resolution equirect, "
                      "with its error bound (integrator=monte_carlo or spp=N: the Monte Carlo integrator)"},
    };
}

std::vector<OptionInfo> option_catalog() {
    return {
        {"roughness", "0.5", "0..1", "all", "perceptual roughness of the `sphere` scene (alpha = r^2)"},
        {"metallic", "0", "0..1", "all", "metalness of the `sphere` scene"},
        {"base_color", "1,1,1", "r,g,b", "all", "base colour of the `sphere` scene"},
        {"env_rotation", "0", "degrees", "all", "turns the environment about +Y"},
        {"frame", "0", "integer", "all", "frame of an animated scene (bumpy_sphere)"},
        {"bump_amplitude", "0.0008", ">=0", "all", "height of the bumpy_sphere normal detail"},
        {"roughness_bias", "0", "-1..1", "all", "stability: added to every sphere's roughness"},
        {"camera_shift", "0", "pixels x,y,0", "all", "stability: moves the camera by a fraction of a pixel"},
        {"bump_frequency", "200", ">0", "all", "spatial frequency of the bumpy_sphere normal detail (radius-1 units)"},
        {"ssaa", "2", "1..16", "mobile,sampled", "n x n rays per pixel (silhouettes)"},
        {"cube_size", "128 (sampled: 256)", "8..2048, power of two", "mobile,sampled", "base size of the cubemaps"},
        {"mips", "7", "1..log2(cube_size)+1", "mobile", "levels of the prefiltered chain"},
        {"prefilter_samples", "64", "1..65536", "mobile", "GGX samples per prefiltered texel"},
        {"mip_mapping", "ue4", "ue4|filament|origin", "mobile", "roughness <-> mip mapping"},
        {"env_brdf", "approx", "approx|lut", "mobile", "EnvBRDFApprox (Karis/Lazarov) or a DFG LUT pass"},
        {"lut_size", "64", "8..512", "mobile", "DFG LUT resolution (env_brdf=lut)"},
        {"diffuse", "sh9", "sh9|irradiance_cube", "mobile", "diffuse irradiance representation"},
        {"dominant_dir", "off", "off|lagarde|filament", "mobile", "specular dominant direction"},
        {"normalization", "off", "off|ue4", "mobile", "UE4 mobile reflection normalisation (MixingAlpha)"},
        {"mix_begin_roughness", "0.1", "0..1", "mobile", "normalisation: roughness where mixing starts"},
        {"mix_end_roughness", "0.3", "0..1", "mobile", "normalisation: roughness where mixing is full"},
        {"mix_largest_weight", "10000", ">0", "mobile", "normalisation: clamp of the mixing weight"},
        {"indirect_irradiance", "sh9", "sh9|number", "mobile", "normalisation: lightmap/ILC brightness"},
        {"storage", "rgba16f", "rgba16f|rgba32f|rgbm8|r11g11b10", "mobile", "prefiltered cube storage"},
        {"rgbm_range", "6", ">0", "mobile", "RGBM range (storage=rgbm8)"},
        {"precision", "highp", "highp|mediump", "mobile", "mediump shades in float16_t"},
        {"fp16", "auto", "auto|native|emulated", "mobile",
         "precision=mediump: native float16_t, or emulated (fp32 rounded to fp16 per operation); auto: native if shaderFloat16"},
        {"specular_aa", "off", "off|tokuyoshi|rjump|toksvig", "mobile", "specular anti-aliasing for low roughness"},
        {"specular_aa_variance", "0.25", ">=0", "mobile", "specular AA: screen-space variance scale"},
        {"specular_aa_threshold", "0.18", ">=0", "mobile", "specular AA: clamp of the added roughness"},
        {"samples", "64", "1..65536", "sampled", "GGX samples per ray"},
        {"min_lod", "0", ">=0", "sampled", "lowest mip a sample may read"},
        {"diffuse_roughness", "0.9", "0..1", "sampled", "roughness from which radiance blends to irradiance"},
        {"seed", "0", "integer", "sampled,reference", "random seed"},
        {"spp", "256", ">=1", "reference", "samples per pixel (selects the Monte Carlo integrator)"},
        {"integrator", "quadrature", "quadrature|monte_carlo", "reference", "quadrature truth (default; monte_carlo when spp is set)"},
        {"truth_tolerance", "0.001", ">0", "reference", "quadrature truth: the coarser level's per-pixel tolerance"},
        {"threads", "0", ">=0", "reference", "CPU threads (0: all)"},
    };
}

void validate_spec(const TestSpec& spec) {
    bool known_method = false;
    std::string names;
    for (auto& m : method_catalog()) {
        known_method |= m.name == spec.method;
        names += (names.empty() ? "" : ", ") + m.name;
    }
    if (!known_method) throw UsageError("unknown method '" + spec.method + "'; valid: " + names);
    std::set<std::string> known;
    for (auto& o : option_catalog())
        if (o.methods == "all" || o.methods.find(spec.method) != std::string::npos) known.insert(o.key);
    spec.options.check_known(known, "method " + spec.method);
    // Enumerated values ("a|b|c" in the catalogue) are checked here too, so a suite file with a
    // misspelt variant fails when it is loaded, not halfway through a run.
    for (auto& o : option_catalog()) {
        if (!spec.options.has(o.key) || o.values.find('|') == std::string::npos || o.values.find("number") != std::string::npos)
            continue;
        std::vector<std::string> allowed;
        size_t start = 0;
        for (size_t bar; (bar = o.values.find('|', start)) != std::string::npos; start = bar + 1)
            allowed.push_back(o.values.substr(start, bar - start));
        allowed.push_back(o.values.substr(start));
        spec.options.get_choice(o.key, allowed[0], allowed);
    }
    build_scene(spec.scene, spec.options);  // unknown scene or bad material option: UsageError
}

Renderer::Renderer(vk::ContextOptions options) : options_(std::move(options)) {}
Renderer::~Renderer() = default;

GpuSession& Renderer::gpu() {
    if (!gpu_) gpu_ = std::make_unique<GpuSession>(options_);
    return *gpu_;
}

const Environment& Renderer::environment(const std::string& spec) {
    auto it = environments_.find(spec);
    if (it != environments_.end()) return *it->second;
    auto env = std::make_unique<Environment>(load_environment(spec));
    return *environments_.emplace(spec, std::move(env)).first->second;
}

nlohmann::json Renderer::driver_json() {
    if (!gpu_) return nlohmann::json::object();
    const auto& i = gpu_->ctx().info();
    return {{"device", i.device_name}, {"driver", i.driver_name}, {"driver_info", i.driver_info},
            {"mesa", i.mesa_version}, {"llvm", i.llvm_version}, {"api", i.api_version}};
}

RenderResult Renderer::render(const TestSpec& spec) {
    validate_spec(spec);
    const Environment& env = environment(spec.env);
    auto t0 = std::chrono::steady_clock::now();
    RenderResult r;
    if (spec.method == "reference") {
        if (!uses_quadrature(spec))
            for (const Sphere& s : build_scene(spec.scene, spec.options).spheres)
                if (s.bump_amplitude > 0)
                    throw UsageError("scene " + spec.scene + ": the Monte Carlo integrator models no normal detail; "
                                     "the quadrature truth does (drop spp / integrator=monte_carlo)");
        r = render_reference(spec, env);
    } else if (spec.method == "mobile") {
        r = render_mobile(gpu(), env, spec);
    } else {
        r = render_sampled(gpu(), env, spec);
    }
    double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.provenance["scene"] = spec.scene;
    r.provenance["env"] = spec.env;
    r.provenance["env_hash"] = env.content_hash;
    r.provenance["env_negatives_clamped"] = env.negatives_clamped;
    r.provenance["options"] = spec.options.values();
    r.provenance["wall_ms"] = wall_ms;
    if (spec.method != "reference") {
        r.provenance["shader_tree_hash"] = vk::shader_tree_hash();
        r.provenance["driver"] = driver_json();
    }
    return r;
}

} // namespace iblcheck
