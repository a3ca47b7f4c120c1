#include "renderer.h"

#include <chrono>
#include <optional>
#include <set>

#include "kernel/errors.h"
#include "kernel/hash.h"
#include "kernel/profile.h"
#include "renderers/environments/environment.h"
#include "renderers/mobile/gpu_session.h"
#include "renderers/mobile/mobile_renderer.h"
#include "renderers/reference/reference.h"
#include "renderers/sampled/sampled_renderer.h"
#include "renderers/scenes/coverage.h"
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

namespace {
// A team's shading (docs/SHADER_CONTRACT.md) runs in the mobile pipeline and replaces the built-in
// split sum, so the options that only select parts of that split sum would select nothing: a test
// that set one would pass for a reason it does not have.
void validate_contract_spec(const TestSpec& spec) {
    if (spec.method != "mobile")
        throw UsageError(spec.shader + ": a team's shading runs in the mobile method only, not in " + spec.method);
    for (const char* key : {"env_brdf", "dominant_dir", "lagarde_roughness", "normalization", "mix_begin_roughness",
                            "mix_end_roughness", "mix_largest_weight", "indirect_irradiance"})
        if (spec.options.has(key))
            throw UsageError("option '" + std::string(key) + "' selects part of the built-in shading; " + spec.shader +
                             " does its own (docs/SHADER_CONTRACT.md)");
}

std::string combined_shader_hash(const std::string& tree, const std::string& ibl_shade) {
    Fnv1a64 h;
    h.update(tree);
    h.update(ibl_shade);
    return h.hex();
}
} // namespace

void validate_spec(const TestSpec& spec) {
    bool known_method = false;
    std::string names;
    for (auto& m : method_catalog()) {
        known_method |= m.name == spec.method;
        names += (names.empty() ? "" : ", ") + m.name;
    }
    if (!known_method) throw UsageError("unknown method '" + spec.method + "'; valid: " + names);
    if (!spec.shader.empty()) validate_contract_spec(spec);
    std::set<std::string> known;
    for (auto& o : option_catalog())
        if (o.read_by(spec.method) && !o.internal) known.insert(o.key);
    spec.options.check_known(known, "method " + spec.method);
    // Enumerated values are checked here too, so a suite file with a misspelt variant fails when
    // it is loaded, not halfway through a run.
    for (auto& o : option_catalog())
        if (o.enumerated() && spec.options.has(o.key)) option_choice(spec.options, o.key);
    build_scene(spec.scene, spec.options); // unknown scene or bad material option: UsageError
}

namespace {
// The GPU precompute's settings of a render of `spec`; none for the CPU truth.
std::optional<PrecomputeSettings> gpu_precompute_settings(const TestSpec& spec) {
    if (spec.method == "mobile") return mobile_precompute_settings(spec);
    if (spec.method == "sampled") return sampled_precompute_settings(spec);
    return std::nullopt;
}
} // namespace

std::string precompute_share_key(const TestSpec& spec) {
    const std::optional<PrecomputeSettings> s = gpu_precompute_settings(spec);
    return s ? precompute_key(spec.env, *s) : "";
}

std::string radiance_chain_share_key(const TestSpec& spec) {
    const std::optional<PrecomputeSettings> s = gpu_precompute_settings(spec);
    return s ? precompute_key(spec.env, chain_settings(*s)) : "";
}

Renderer::Renderer(vk::ContextOptions options) : options_(std::move(options)) {}
Renderer::~Renderer() = default;

GpuSession& Renderer::gpu() {
    if (!gpu_) {
        ProfileStage stage("vulkan_init"); // the instance, lavapipe's device, once per worker
        gpu_ = std::make_unique<GpuSession>(options_);
    }
    return *gpu_;
}

const Environment& Renderer::environment(const std::string& spec) {
    auto it = environments_.find(spec);
    if (it != environments_.end()) return *it->second;
    ProfileStage stage("environment");
    auto env = std::make_unique<Environment>(load_environment(spec));
    return *environments_.emplace(spec, std::move(env)).first->second;
}

nlohmann::json Renderer::driver_json() {
    if (!gpu_) return nlohmann::json::object();
    const auto& i = gpu_->ctx().info();
    return {{"device", i.device_name}, {"driver", i.driver_name}, {"driver_info", i.driver_info},
            {"mesa", i.mesa_version},  {"llvm", i.llvm_version},  {"api", i.api_version}};
}

RenderResult Renderer::render(const TestSpec& spec) {
    ProfileStage stage("render_other"); // validation, the source hashes, provenance: what no nested stage names
    validate_spec(spec);
    const Environment& env = environment(spec.env);
    auto t0 = std::chrono::steady_clock::now();
    RenderResult r;
    if (spec.method == "reference") {
        if (!uses_quadrature(spec))
            for (const Sphere& s : build_scene(spec.scene, spec.options).spheres)
                if (s.bump_amplitude > 0)
                    throw UsageError("scene " + spec.scene +
                                     ": the Monte Carlo integrator models no normal detail; "
                                     "the quadrature truth does (drop spp / integrator=monte_carlo)");
        r = render_reference(spec, env);
    } else if (spec.method == "mobile") {
        r = render_mobile(gpu(), env, spec);
    } else {
        r = render_sampled(gpu(), env, spec);
    }
    double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.provenance["scene"] = spec.scene;
    r.provenance["env"] = environment_label(spec.env, spec.env_name); // no machine's absolute path in a sidecar
    r.provenance["env_hash"] = env.content_hash;
    r.provenance["env_negatives_clamped"] = env.negatives_clamped;
    r.provenance["options"] = spec.options.values();
    r.provenance["wall_ms"] = wall_ms;
    if (spec.method != "reference") {
        // A team's shading file is part of the shader source (the report's "since the baselines").
        r.provenance["shader_tree_hash"] = spec.shader.empty()
                                               ? vk::shader_tree_hash()
                                               : combined_shader_hash(vk::shader_tree_hash(), vk::ibl_shade_hash(spec.shader));
        r.provenance["shader_files"] = vk::shader_file_hashes(); // which files changed, not only that one did
        r.provenance["driver"] = driver_json();
    }
    r.coverage = sphere_coverage(build_scene(spec.scene, spec.options), r.image.cols, r.image.rows);
    return r;
}

} // namespace iblcheck
