// `iblcheck render` and `iblcheck list`.
#include <fmt/core.h>

#include <filesystem>

#include "commands.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/output_files.h"
#include "metrics/display_transform.h"
#include "renderers/environments/environment.h"
#include "renderers/renderer.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::cli {

namespace {
void parse_size(const std::string& s, int& w, int& h) {
    if (s.empty()) return;
    if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 8192 || h > 8192)
        throw UsageError("--size '" + s + "' is not WxH (1..8192)");
}

// Timings per pass, their total, and the cost figures, one per line.
void print_render_summary(FILE* human, const RenderResult& r) {
    double total = 0;
    for (auto& t : r.timings) {
        fmt::print(human, "{:<20} {:9.3f} ms  {}{}\n", t.name, t.ms, t.gpu ? "gpu" : "cpu", t.precompute ? "  precompute" : "");
        total += t.ms;
    }
    fmt::print(human, "{:<20} {:9.3f} ms\n", "total", total);
    fmt::print(human, "texture samples/px  {:.2f}\n", r.texture_fetches_per_pixel);
    // The deterministic cost (issue 14): the same on every run, where the times above are not.
    if (r.shader_instructions_per_pixel > 0) fmt::print(human, "spirv instr/px      {:.2f}\n", r.shader_instructions_per_pixel);
    if (r.texture_bytes > 0) fmt::print(human, "env texture         {} texels, {} bytes\n", r.texel_count, r.texture_bytes);
}

// `render --json`: provenance, cost and timings.
nlohmann::json render_json(const RenderResult& r) {
    nlohmann::json j;
    j["provenance"] = r.provenance;
    j["texture_fetches_per_pixel"] = r.texture_fetches_per_pixel;
    j["shader_instructions_per_pixel"] = r.shader_instructions_per_pixel;
    if (r.texture_bytes > 0) {
        j["texture_bytes"] = r.texture_bytes;
        j["texel_count"] = r.texel_count;
    }
    for (auto& t : r.timings)
        j["timings"].push_back({{"pass", t.name}, {"ms", t.ms}, {"gpu", t.gpu}, {"precompute", t.precompute}});
    return j;
}

// To stdout for "-", else to the file.
void write_render_json(const std::string& path, const nlohmann::json& j) {
    if (path == "-") {
        fmt::print("{}\n", j.dump(2));
    } else {
        write_file_atomically(path, j.dump(2) + "\n", "render JSON");
    }
}
} // namespace

void register_list_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("list", "List scenes, methods, environments and options");
    cmd->callback([&exit_code] {
        fmt::print("scenes:\n");
        for (auto& s : scene_catalog()) fmt::print("  {:<20} {}\n", s.name, s.description);
        fmt::print("methods:\n");
        for (auto& m : method_catalog()) fmt::print("  {:<20} {}\n", m.name, m.description);
        fmt::print("environments:\n");
        for (auto& e : environment_catalog()) fmt::print("  {:<20} {}\n", e.spec, e.description);
        fmt::print("options (--set key=value; methods that read them):\n");
        for (auto& o : option_catalog())
            if (!o.internal)
                fmt::print("  {:<22} default {:<10} values {:<34} [{}] {}\n", o.key, o.default_text(), o.values, o.methods,
                           o.description);
        exit_code = kExitPass;
    });
}

void register_render_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("render", "Render a scene with one method");
    static std::string scene = "sphere", method = "mobile", env = "studio", size, out, json_out, device, shader;
    static std::vector<std::string> sets;
    static bool force = false;
    cmd->add_option("--scene", scene, "Scene name (iblcheck list)")->capture_default_str();
    cmd->add_option("--method", method, "mobile | sampled | reference")->capture_default_str();
    cmd->add_option("--env", env, "Environment spec (iblcheck list)")->capture_default_str();
    cmd->add_option("--size", size, "Image size WxH (default: the scene's)");
    cmd->add_option("--set", sets, "Option key=value (repeatable)");
    cmd->add_option("--shader", shader, "mobile: a team's IBL shading file instead of the built-in (docs/SHADER_CONTRACT.md)");
    cmd->add_option("--out", out, "Output EXR (a tone-mapped PNG is written beside it)");
    cmd->add_option("--json", json_out, "Write timings and provenance as JSON to this file ('-' for stdout)");
    cmd->add_option("--device", device, "Vulkan device/driver name substring (default: lavapipe)");
    cmd->add_flag("--force", force, "Overwrite existing output files (--out, its PNG, --json; never the --env file)");
    cmd->callback([&exit_code] {
        TestSpec spec;
        spec.scene = scene;
        spec.method = method;
        spec.env = env;
        parse_size(size, spec.width, spec.height);
        for (auto& s : sets) spec.options.set_from_string(s);
        if (!shader.empty()) spec.shader = std::filesystem::absolute(shader).lexically_normal().string();
        namespace fs = std::filesystem;
        const fs::path png = out.empty() ? fs::path() : fs::path(out).replace_extension(".png");
        // The environment file is the render's input: never overwritten, not even with --force.
        check_output_file(out, "--out", force, {env});
        check_output_file(png, "--out (its PNG)", force, {env});
        check_distinct_outputs(out, "--out", png, "--out's PNG"); // --out x.png
        if (json_out != "-") {
            check_output_file(json_out, "--json", force, {env});
            check_distinct_outputs(json_out, "--json", out, "--out");
            check_distinct_outputs(json_out, "--json", png, "--out's PNG");
        }
        vk::ContextOptions vo;
        vo.device = device;
        Renderer renderer(vo);
        const RenderResult r = renderer.render(spec);
        // With --json - the JSON owns stdout; the human-readable lines go to stderr.
        FILE* human = json_out == "-" ? stderr : stdout;
        print_render_summary(human, r);
        if (!out.empty()) {
            write_exr(out, r.image);
            write_png(png.string(), display_transform(r.image));
            fmt::print(human, "wrote {} and {}\n", out, png.string());
        }
        if (!json_out.empty()) write_render_json(json_out, render_json(r));
        // Non-finite pixels or coverage are the shader's fault: a regression (exit 1), after the
        // files are written so the pixels can be inspected.
        if (NonFinite nf = find_non_finite(r.image); nf.count) {
            fmt::print(stderr, "error: {} {} under {}: the render has {}\n", method, scene, env, nf.describe());
            exit_code = kExitRegression;
            return;
        }
        if (!r.non_finite_coverage.empty()) { // NaN/Inf coverage: the shader's fault too
            fmt::print(stderr, "error: {} {} under {}: {}\n", method, scene, env, r.non_finite_coverage);
            exit_code = kExitRegression;
            return;
        }
        exit_code = kExitPass;
    });
}

} // namespace iblcheck::cli
