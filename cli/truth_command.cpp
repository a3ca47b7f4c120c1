// `iblcheck truth`: renders the quadrature truth of a scene under an environment (a built-in spec or the
// user's own .exr/.hdr) and writes it as a golden with its JSON sidecar (harness/truth/truth_golden.h):
// the error bound (two refinement levels' difference: relative RMSE, mean FLIP, per sphere, worst pixel)
// and issue 16's criterion verdict. Progress and an ETA go to stderr, one updating line on a terminal.
//   --frames N                  the temporal truth (frames stacked vertically in one golden)
//   --integrator monte_carlo    the Monte Carlo integrator at --spp N, lighting seed --seed K, with its noise
//                               floor against a second render with seed K + 1 (monte_carlo_golden.h);
//                               --tiles WxH prints that noise floor per tile
//   --compare OLD.exr           prints the mean FLIP and relative RMSE between the new golden and OLD
//   --print-name                prints the golden's name (harness/golden_store.h's reference_key) and exits
// Nothing is overwritten without --force. Exit 0: written, criterion met; 1: written, criterion NOT met.
#include <fmt/core.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.h"
#include "harness/golden_store.h"
#include "harness/truth/monte_carlo_golden.h"
#include "harness/truth/truth_golden.h"
#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "kernel/output_files.h"
#include "kernel/shell_quote.h"
#include "renderers/environments/environment.h"
#include "renderers/option_table.h"

namespace iblcheck::cli {

namespace {
// "[truth] 42% 0:31 elapsed, ETA 0:43": rewritten in place on a terminal, every 10 % otherwise.
class ProgressLine {
  public:
    explicit ProgressLine(std::string what) : what_(std::move(what)), tty_(isatty(fileno(stderr)) != 0) {}
    void operator()(double f) {
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        const int pct = int(f * 100);
        if (!tty_ && pct / 10 == last_ / 10) return;
        if (tty_ && pct == last_ && t - last_t_ < 1) return;
        last_ = pct, last_t_ = t;
        const std::string eta = f > 0.02 ? clock(t * (1 - f) / f) : std::string("?");
        fmt::print(stderr, "{}[truth] {}: {:3d}%  {} elapsed, ETA {}{}", tty_ ? "\r" : "", what_, pct, clock(t), eta,
                   tty_ ? "   " : "\n");
        std::fflush(stderr);
    }
    void done() {
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        fmt::print(stderr, "{}[truth] {}: done in {}{}\n", tty_ ? "\r" : "", what_, clock(t), tty_ ? "            " : "");
    }

  private:
    static std::string clock(double s) {
        const int v = int(s + 0.5);
        return fmt::format("{}:{:02d}", v / 60, v % 60);
    }
    std::string what_;
    bool tty_;
    int last_ = -100;
    double last_t_ = -1;
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};
// The command line, as parsed.
struct TruthArgs {
    std::string scene = "roughness_sweep", env, env_name, size, goldens, out, integrator = "quadrature", compare, tiles, command;
    std::vector<std::string> sets;
    bool force = false, print_name = false;
    int frames = 0, spp = option_int(OptionMap{}, "spp", "reference"), seed = option_int(OptionMap{}, "seed", "reference");
    bool spp_given = false, seed_given = false;
};

// The golden's path: --out, else the golden store (--goldens, else the runner's default) under exactly the
// key a suite test with this scene, environment, size and material reads (reference/<key>.exr). It used to
// be <key>.exr in the current folder, with a key the runner did not read. Refused if it or its sidecar
// exists without --force, and always when it is an input (the --env file, or --compare's OLD.exr).
std::string golden_path(const TruthArgs& a, const TestSpec& keyed) {
    namespace fs = std::filesystem;
    const GoldenStore store(a.goldens);
    std::string exr = !a.out.empty() ? a.out
                      : a.frames > 0 ? store.reference_sequence_path(keyed, a.frames).string()
                                     : store.reference_path(keyed).string();
    std::error_code ec;
    if (a.out.empty()) fs::create_directories(fs::path(exr).parent_path(), ec); // a new golden root: its reference/
    for (const fs::path& p : {fs::path(exr), fs::path(exr).replace_extension(".json")})
        check_output_file(p, "--out", a.force, {a.env, a.compare});
    return exr;
}

// The regenerating command as recorded: --command's text, else this command without absolute paths (a file
// environment by its name).
std::string recorded_command(const TruthArgs& a, const std::string& env) {
    if (!a.command.empty()) return a.command;
    std::string c = fmt::format("iblcheck truth --scene {} --env {}", shell_arg(a.scene), shell_arg(env));
    if (!a.size.empty()) c += " --size " + a.size;
    if (a.integrator == "monte_carlo") c += fmt::format(" --integrator monte_carlo --spp {} --seed {}", a.spp, a.seed);
    for (auto& s : a.sets) c += " --set " + shell_arg(s);
    if (a.frames > 0) c += " --frames " + std::to_string(a.frames);
    return c;
}

std::string sidecar(const std::string& exr) { return std::filesystem::path(exr).replace_extension(".json").string(); }

// WxH, e.g. 48x48.
std::pair<int, int> parse_tiles(const std::string& t) {
    int w = 0, h = 0;
    char rest = 0;
    if (std::sscanf(t.c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w < 1 || h < 1)
        throw UsageError("--tiles: expected WxH, e.g. 48x48, got '" + t + "'");
    return {w, h};
}

// --size WxH, as a suite's "size" (the key gets __WxH, as the runner's does).
void parse_truth_size(const std::string& s, int& w, int& h) {
    if (s.empty()) return;
    char rest = 0;
    if (std::sscanf(s.c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w < 1 || h < 1 || w > 8192 || h > 8192)
        throw UsageError("--size '" + s + "' is not WxH (1..8192)");
}

void check_combinations(const TruthArgs& a) {
    const bool mc = a.integrator == "monte_carlo";
    if (!mc && (a.spp_given || a.seed_given || !a.tiles.empty()))
        throw UsageError("--spp, --seed and --tiles are options of --integrator monte_carlo");
    if (mc && a.frames > 0) throw UsageError("--frames: the temporal truth is the quadrature's (no --integrator monte_carlo)");
    if (mc && a.spp < 1) throw UsageError("--spp: must be >= 1");
    if (!a.tiles.empty()) parse_tiles(a.tiles);
    // Read after the render: a missing file or a FIFO is refused before the minutes it takes.
    if (!a.compare.empty()) require_regular_file(a.compare);
}

void print_comparison(const std::string& new_exr, const std::string& old_exr) {
    const truth::GoldenDifference d = truth::golden_difference(new_exr, old_exr);
    fmt::print("against {}: mean FLIP {:.5f}, relative RMSE {:.4f} %\n", old_exr, d.mean_flip, 100 * d.relative_rmse);
}

int run_sequence(const truth::GoldenRequest& req, int frames, ProgressLine& line) {
    truth::SequenceRequest sr;
    sr.spec = req.spec, sr.frames = frames, sr.bound_frames = {0, frames / 2}, sr.out_exr = req.out_exr;
    sr.command = req.command;
    sr.progress = req.progress;
    const nlohmann::json m = truth::write_truth_sequence_golden(sr);
    line.done();
    const auto& b = m["error_bound"];
    fmt::print("wrote {} and {} ({} frames of {}x{}, {:.1f} s)\n", req.out_exr, sidecar(req.out_exr), frames,
               m["width"].get<int>(), m["height"].get<int>(), m["time_s"].get<double>());
    fmt::print("error bound (frames {} and {} against the finer level): relative RMSE <= {:.4f} %, mean FLIP <= {:.5f}, "
               "LDR FLIP <= {:.5f}\n",
               sr.bound_frames[0], sr.bound_frames[1], 100 * b["relative_rmse_max"].get<double>(),
               b["mean_flip_max"].get<double>(), b["mean_flip_ldr_max"].get<double>());
    const auto& c = b["criterion"];
    const bool met = c["met"].get<bool>();
    fmt::print("criterion (LDR FLIP < {}, relied on by the temporal suite; mean FLIP < {}; relative RMSE < {} %) -> {}\n",
               c["mean_flip_ldr_below"].get<double>(), c["mean_flip_below"].get<double>(),
               100 * c["relative_rmse_below"].get<double>(), met ? "met" : "NOT met");
    return met ? kExitPass : kExitRegression;
}

int run_quadrature(const truth::GoldenRequest& req, ProgressLine& line) {
    const truth::GoldenWritten g = truth::write_truth_golden(req);
    line.done();
    const auto& b = g.meta["error_bound"];
    fmt::print("wrote {} and {} ({}x{}, {:.1f} s)\n", req.out_exr, sidecar(req.out_exr), g.meta["width"].get<int>(),
               g.meta["height"].get<int>(), g.meta["time_s"].get<double>());
    fmt::print("error bound (coarser vs finer level): relative RMSE {:.4f} %, mean FLIP {:.5f}, worst pixel {:.4f} "
               "({:.2f} % relative) -> criterion {}\n",
               100 * b["relative_rmse"].get<double>(), g.mean_flip, b["worst_pixel"].get<double>(),
               100 * b["worst_pixel_relative"].get<double>(), g.criterion_met ? "met" : "NOT met");
    for (const auto& s : b["per_sphere"])
        fmt::print("  {:<16} relative RMSE {:.4f} %  mean FLIP {:.5f}  worst pixel {:.4f}\n", s["label"].get<std::string>(),
                   100 * s["relative_rmse"].get<double>(), s["mean_flip"].get<double>(), s["worst_pixel"].get<double>());
    return g.criterion_met ? kExitPass : kExitRegression;
}

int run_monte_carlo(const TruthArgs& a, const truth::GoldenRequest& req) {
    reference::MonteCarloGoldenRequest mr;
    mr.spec = req.spec, mr.spp = a.spp, mr.seed = a.seed, mr.out_exr = req.out_exr, mr.command = req.command;
    fmt::print(stderr, "[truth] Monte Carlo, {} spp, seeds {} and {} (noise floor)...\n", a.spp, a.seed, a.seed + 1);
    const reference::MonteCarloGoldenWritten g = reference::write_monte_carlo_golden(mr);
    const auto& nf = g.meta["noise_floor"];
    fmt::print("wrote {} and {} ({}x{}, {} spp, {:.1f} s)\n", req.out_exr, sidecar(req.out_exr), g.meta["width"].get<int>(),
               g.meta["height"].get<int>(), a.spp, g.meta["time_s"].get<double>());
    fmt::print("noise floor (seeds {} and {}): relative RMSE {:.4f} %, mean FLIP {:.5f} -> criterion {}\n", a.seed, a.seed + 1,
               100 * nf["relative_rmse"].get<double>(), nf["mean_flip"].get<double>(), g.criterion_met ? "met" : "NOT met");
    if (!a.tiles.empty()) {
        const auto [w, h] = parse_tiles(a.tiles);
        fmt::print("{}", reference::noise_floor_by_tile(g, w, h));
    }
    return g.criterion_met ? kExitPass : kExitRegression;
}

int run_truth(const TruthArgs& a) {
    check_combinations(a);
    truth::GoldenRequest req;
    req.spec.method = "reference";
    req.spec.scene = a.scene;
    req.spec.env = a.env;
    req.spec.env_name = a.env_name;
    if (!a.env_name.empty() && !is_environment_file(a.env))
        throw UsageError("--env-name names an environment file; " + a.env + " is a built-in environment");
    parse_truth_size(a.size, req.spec.width, req.spec.height);
    for (auto& s : a.sets) req.spec.options.set_from_string(s);
    if (req.spec.options.has("split_sum")) // a rung of `iblcheck explain`, not a truth: never a golden
        throw UsageError(
            "--set split_sum: the split sum's rungs are approximations, not a truth; `iblcheck explain` renders them");
    if (a.print_name) { // the regeneration script's names: the golden store's, never a copy of its rule
        fmt::print("{}\n", a.frames > 0 ? reference_sequence_key(req.spec, a.frames) : reference_key(req.spec));
        return kExitPass;
    }
    // The golden store's key: the environment by its stable name (environment_label), never its folder.
    req.out_exr = golden_path(a, req.spec);
    req.command = recorded_command(a, truth::portable_env_spec(req.spec));
    int rc;
    if (a.integrator == "monte_carlo") {
        rc = run_monte_carlo(a, req);
    } else {
        ProgressLine line(a.scene + " / " + truth::portable_env_spec(req.spec));
        req.progress = [&line](double f) { line(f); };
        rc = a.frames > 0 ? run_sequence(req, a.frames, line) : run_quadrature(req, line);
    }
    if (!a.compare.empty()) print_comparison(req.out_exr, a.compare);
    return rc;
}
} // namespace

void register_truth_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("truth", "Render the deterministic quadrature truth (or the Monte Carlo integrator) of "
                                            "a scene and write it as a reference golden + JSON sidecar with its error bound");
    static TruthArgs a;
    cmd->add_option("--scene", a.scene, "Scene name (iblcheck list)")->capture_default_str();
    cmd->add_option("--env", a.env, "Environment: a spec (iblcheck list) or a path to your own .exr/.hdr")->required();
    cmd->add_option("--out", a.out,
                    "Golden EXR to write (default: the golden store's reference/<key>.exr, the file a suite test "
                    "with this scene, environment, size and material reads); the sidecar is the same path with .json");
    cmd->add_option("--goldens", a.goldens, "Golden folder to write into (default: goldens/, as run and bless)");
    cmd->add_option("--env-name", a.env_name,
                    "The stable name of an environment file, as the suite gives it ({\"file\": ..., \"name\": ...}; "
                    "default: its file name): the golden's key and the name recorded in its sidecar");
    cmd->add_option("--size", a.size, "Image size WxH, as the suite test's \"size\" (default: the scene's)");
    cmd->add_option("--set", a.sets,
                    "Option key=value (repeatable): material options, env_rotation, threads, "
                    "truth_tolerance (the coarser level's pixel tolerance)");
    cmd->add_option("--frames", a.frames,
                    "Render the temporal truth: frames 0..N-1 (option frame) stacked vertically "
                    "in one golden, as the temporal suite reads it (reference/<key>__frames=N.exr)")
        ->check(CLI::Range(1, 1 << 20)); // --frames 0 is not "no sequence": it is a mistake
    cmd->add_option("--integrator", a.integrator,
                    "quadrature (the deterministic truth) or monte_carlo (the Monte Carlo integrator, with its noise "
                    "floor between seeds K and K+1 in the sidecar; the near-mirror golden)")
        ->check(CLI::IsMember({"quadrature", "monte_carlo"}))
        ->capture_default_str();
    cmd->add_option("--spp", a.spp, "monte_carlo: lighting samples per pixel")
        ->check(CLI::Range(1, 1 << 30))
        ->capture_default_str();
    cmd->add_option("--seed", a.seed, "monte_carlo: the golden's lighting seed K (the noise floor renders K+1 too)")
        ->capture_default_str();
    cmd->add_option("--tiles", a.tiles,
                    "monte_carlo: also print the noise floor per WxH tile (48x48: one sphere of the "
                    "roughness sweep)");
    cmd->add_option("--compare", a.compare, "Print the mean FLIP and relative RMSE between the new golden and OLD.exr");
    cmd->add_option("--command", a.command,
                    "The regenerating command recorded in the sidecar (default: this iblcheck truth command)");
    cmd->add_flag("--force", a.force, "Overwrite existing output files");
    cmd->add_flag("--print-name", a.print_name,
                  "Print the golden's name, the key of reference/<name>.exr that a suite test with this scene, "
                  "environment, size, material (and --frames) reads, and exit: nothing is rendered or written");
    cmd->callback([&exit_code, cmd] {
        a.spp_given = cmd->count("--spp") > 0;
        a.seed_given = cmd->count("--seed") > 0;
        exit_code = run_truth(a);
    });
}

} // namespace iblcheck::cli
