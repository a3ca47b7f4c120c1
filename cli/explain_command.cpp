// `iblcheck explain`: the error budget of a mobile configuration per sphere (harness/error_budget.h).
#include <fmt/core.h>

#include <chrono>
#include <sstream>

#include "commands.h"
#include "harness/error_budget.h"
#include "harness/golden_store.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/output_files.h"
#include "renderers/renderer.h"

namespace iblcheck::cli {

namespace {

struct ExplainArgs {
    std::string scene = "roughness_sweep", env = "studio", json_out, order, goldens;
    std::vector<std::string> sets;
    bool force = false;
};

std::vector<std::string> split_list(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The truth: the reference golden when it exists and no truth control is set, else rendered.
cv::Mat truth_image(Renderer& renderer, const TestSpec& truth, const std::string& goldens, nlohmann::json& info) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!truth.options.has("truth_tolerance")) {
        GoldenStore store(goldens);
        if (auto g = store.reference(truth)) {
            info = {{"source", store.relative(g->image_path)}, {"seconds", seconds_since(t0)}};
            return g->image;
        }
    }
    const RenderResult r = renderer.render(truth);
    info = {{"source", "rendered"}, {"options", truth.options.values()}, {"seconds", seconds_since(t0)}};
    return r.image;
}

void run_explain(const ExplainArgs& a, int& exit_code) {
    OptionMap config;
    for (const auto& s : a.sets) config.set_from_string(s);
    check_output_file(a.json_out, "--json", a.force, {a.env});
    const BudgetPlan plan = plan_budget(a.scene, a.env, config, split_list(a.order));
    Renderer renderer;
    nlohmann::json truth_info;
    const cv::Mat truth = truth_image(renderer, plan.truth, a.goldens, truth_info);
    fmt::print(stderr, "truth: {} ({:.1f} s)\n", truth_info["source"].get<std::string>(), truth_info["seconds"].get<double>());
    SphereCoverage coverage;
    cv::Mat previous = truth;
    std::vector<RungErrors> steps;
    auto render = [&](const BudgetRung& r, nlohmann::json& times, const char* what) {
        const auto t0 = std::chrono::steady_clock::now();
        const RenderResult res = renderer.render(r.spec);
        if (res.image.size() != truth.size())
            throw InputError(fmt::format("{}: the truth is {}x{}, the rung {}x{}", truth_info["source"].get<std::string>(),
                                         truth.cols, truth.rows, res.image.cols, res.image.rows));
        if (find_non_finite(res.image).count) throw InputError("rung " + r.label + ": the render has NaN/Inf pixels");
        coverage = res.coverage;
        times.push_back({{"key", r.key}, {"what", what}, {"seconds", seconds_since(t0)}});
        fmt::print(stderr, "  {:<8} {:<44} {:7.1f} s\n", what, r.label, seconds_since(t0));
        if (std::string(what) == "ladder")
            steps.push_back(measure_errors(previous, res.image, coverage, 0)), previous = res.image;
        return measure_errors(truth, res.image, coverage, 0);
    };
    nlohmann::json times = nlohmann::json::array();
    std::vector<RungErrors> ladder, isolated;
    for (const BudgetRung& r : plan.ladder) ladder.push_back(render(r, times, "ladder"));
    for (const BudgetRung& r : plan.isolated) isolated.push_back(render(r, times, "alone"));
    nlohmann::json j = budget_json(plan, ladder, isolated, coverage, steps);
    j["scene"] = a.scene, j["env"] = a.env, j["config"] = config.values(), j["truth"] = truth_info, j["render_seconds"] = times;
    fmt::print("{} under {}{}\n{}", a.scene, a.env, config.values().empty() ? "" : " with " + config.canonical(),
               budget_table(j));
    if (!a.json_out.empty()) {
        write_file_atomically(a.json_out, j.dump(2) + "\n", "error budget JSON");
    }
    exit_code = kExitPass;
}

} // namespace

void register_explain_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("explain", "Error budget of a mobile configuration against the truth, per sphere and per "
                                              "approximation (the ladder of docs/DESIGN.md, harness/error_budget.h)");
    static ExplainArgs a;
    cmd->add_option("--scene", a.scene, "Scene name (iblcheck list)")->capture_default_str();
    cmd->add_option("--env", a.env, "Environment spec (iblcheck list)")->capture_default_str();
    cmd->add_option("--set", a.sets,
                    "Option key=value of the mobile configuration (repeatable); truth_tolerance and threads "
                    "go to the CPU rungs (and render the truth instead of reading its golden)");
    cmd->add_option("--order", a.order,
                    "GPU steps to walk first, comma-separated (the order dependence), e.g. "
                    "storage,prefilter_samples");
    cmd->add_option("--json", a.json_out, "Write the budget as JSON to this file");
    cmd->add_option("--goldens", a.goldens, "Golden root (default: $IBLCHECK_GOLDEN_DIR, else <source>/goldens)");
    cmd->add_flag("--force", a.force, "Overwrite --json");
    cmd->callback([&exit_code] { run_explain(a, exit_code); });
}

} // namespace iblcheck::cli
