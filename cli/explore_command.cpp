// `iblcheck explore`: the most accurate mobile configuration for a cost, per environment
// (harness/explore.h): a coordinate descent against the truth, the Pareto fronts, a suite of winners.
#include <fmt/core.h>

#include <chrono>

#include "commands.h"
#include "harness/error_budget.h"
#include "harness/explore.h"
#include "harness/golden_store.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/output_files.h"
#include "renderers/renderer.h"

namespace iblcheck::cli {

namespace {

struct ExploreArgs {
    std::string scene = "roughness_sweep", json_out, suite_out, goldens, size;
    std::vector<std::string> envs{"studio", "sky_sun", "blender:sunrise"}, axes;
    double budget = 0.10;
    int passes = 3;
    bool force = false;
};

TestSpec base_spec(const ExploreArgs& a, const std::string& env, const std::string& method) {
    TestSpec t;
    t.scene = a.scene, t.env = env, t.method = method;
    if (!a.size.empty() && std::sscanf(a.size.c_str(), "%dx%d", &t.width, &t.height) != 2)
        throw UsageError("--size '" + a.size + "': expected WxH, e.g. 64x32");
    return t;
}

// The truth: the reference golden of that scene, environment and size when it exists, else rendered
// (the quadrature truth on the CPU: minutes at the scenes' sizes, seconds at 64x32).
cv::Mat truth_of(Renderer& renderer, const TestSpec& truth, const std::string& goldens, std::string& source) {
    GoldenStore store(goldens);
    if (auto g = store.reference(truth)) {
        source = store.relative(g->image_path);
        return g->image;
    }
    source = "rendered";
    return renderer.render(truth).image;
}

nlohmann::json explore_env(const ExploreArgs& a, const std::vector<ExploreAxis>& axes, Renderer& renderer,
                           const std::string& env) {
    std::string source;
    const cv::Mat truth = truth_of(renderer, base_spec(a, env, "reference"), a.goldens, source);
    fmt::print(stderr, "{} under {}: truth {}\n", a.scene, env, source);
    auto evaluate = [&](const OptionMap& o) {
        TestSpec t = base_spec(a, env, "mobile");
        t.options = o;
        const auto t0 = std::chrono::steady_clock::now();
        const RenderResult r = renderer.render(t);
        if (r.image.size() != truth.size())
            throw InputError(fmt::format("{}: the truth is {}x{}, the render {}x{}", source, truth.cols, truth.rows, r.image.cols,
                                         r.image.rows));
        if (find_non_finite(r.image).count) throw InputError("explore: " + o.canonical() + ": the render has NaN/Inf pixels");
        ExplorePoint p;
        p.flip = measure_errors(truth, r.image, r.coverage, 0).image.flip;
        p.ipp = r.shader_instructions_per_pixel, p.fetches = r.texture_fetches_per_pixel, p.bytes = r.texture_bytes;
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        fmt::print(stderr, "  {:<60} FLIP {:.4f} {:7.0f} instr/px ({:.1f} s)\n", o.values().empty() ? "default" : o.canonical(),
                   p.flip, p.ipp, s);
        return p;
    };
    const ExploreResult r = explore_descent(axes, evaluate, a.budget, a.passes);
    nlohmann::json j = explore_json(r, axes);
    j["env"] = env, j["truth"] = source;
    fmt::print("{} under {}\n{}\n", a.scene, env, explore_table(j));
    return j;
}

// A suite holding each environment's winner: its baseline gates the shader, its reference band the
// accuracy the search found (bless the suite once to approve both).
nlohmann::json winners_suite(const ExploreArgs& a, const nlohmann::json& envs) {
    nlohmann::json tests = nlohmann::json::array();
    for (const auto& e : envs) {
        nlohmann::json t = {{"scene", a.scene}, {"method", "mobile"}, {"env", e["env"]}, {"options", e["best"]["options"]}};
        if (!a.size.empty()) t["size"] = a.size;
        tests.push_back(t);
    }
    return {{"suite", "explore_winners"},
            {"description", "The configurations `iblcheck explore` found most accurate within +" +
                                fmt::format("{:.0f}", 100 * a.budget) +
                                " % of the default's SPIR-V instructions per pixel, one per environment (written by "
                                "iblcheck explore --suite-out). The baseline gates shader changes; the reference band "
                                "holds the accuracy against the truth."},
            {"defaults",
             {{"jobs", 1},
              {"baseline_tolerances",
               {{"flip.mean", {{"max", 0.001}}}, {"flip.p99", {{"max", 0.02}}}, {"flip.block_max", {{"max", 0.01}}}}},
              {"reference_band", {{"flip.mean", {{"below", 0.2}, {"above", 0.1}, {"abs", 0.002}}}}}}},
            {"tests", tests}};
}

void write_json(const std::string& path, const nlohmann::json& j) {
    write_file_atomically(path, j.dump(2) + "\n", "explore JSON");
}

void run_explore(const ExploreArgs& a, int& exit_code) {
    std::vector<ExploreAxis> axes;
    for (const std::string& s : a.axes) axes.push_back(parse_explore_axis(s));
    if (axes.empty()) axes = default_explore_axes();
    if (a.budget < 0) throw UsageError("--budget must be >= 0");
    check_output_file(a.json_out, "--json", a.force, {});
    check_output_file(a.suite_out, "--suite-out", a.force, {});
    Renderer renderer;
    nlohmann::json envs = nlohmann::json::array();
    for (const std::string& env : a.envs) envs.push_back(explore_env(a, axes, renderer, env));
    const nlohmann::json out = {{"kind", "iblcheck-explore"}, {"scene", a.scene}, {"budget", a.budget}, {"environments", envs}};
    if (!a.json_out.empty()) write_json(a.json_out, out);
    if (!a.suite_out.empty()) write_json(a.suite_out, winners_suite(a, envs));
    exit_code = kExitPass;
}

} // namespace

void register_explore_command(CLI::App& app, int& exit_code) {
    auto* cmd =
        app.add_subcommand("explore", "Search the mobile option space against the truth for the most accurate configuration "
                                      "for a cost; print the Pareto fronts (harness/explore.h)");
    static ExploreArgs a;
    cmd->add_option("--scene", a.scene, "Scene name (iblcheck list)")->capture_default_str();
    cmd->add_option("--env", a.envs, "Environments, one search each (repeatable)")->capture_default_str();
    cmd->add_option("--axis", a.axes,
                    "An axis key=v1|v2|... (repeatable; replaces the default axes: diffuse, dominant_dir, lagarde_roughness, "
                    "mip_mapping, env_brdf, normalization, specular_aa, cube_size, prefilter_samples, storage, precision, ssaa)");
    cmd->add_option("--size", a.size, "Image size WxH (default: the scene's; the truth is rendered where no golden has it)");
    cmd->add_option("--budget", a.budget, "Allowed increase of SPIR-V instructions per pixel over the default")
        ->capture_default_str();
    cmd->add_option("--passes", a.passes, "Most passes over the axes")->capture_default_str()->check(CLI::Range(1, 20));
    cmd->add_option("--json", a.json_out, "Write every environment's search, fronts and winner as JSON");
    cmd->add_option("--suite-out", a.suite_out, "Write a suite of the winners (one test per environment)");
    cmd->add_option("--goldens", a.goldens, "Golden root (default: $IBLCHECK_GOLDEN_DIR, else <source>/goldens)");
    cmd->add_flag("--force", a.force, "Overwrite --json and --suite-out");
    cmd->callback([&exit_code] { run_explore(a, exit_code); });
}

} // namespace iblcheck::cli
