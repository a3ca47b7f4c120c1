// `iblcheck truth`: renders the quadrature truth of a scene under an environment (a built-in spec or the
// user's own .exr/.hdr) and writes it as a golden with its JSON sidecar (renderers/reference/truth_golden.h):
// the error bound (two refinement levels' difference: relative RMSE, mean FLIP, per sphere, worst pixel)
// and issue 16's criterion verdict. Progress and an ETA go to stderr, one updating line on a terminal.
#include <fmt/core.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.h"
#include "harness/common/errors.h"
#include "harness/golden_store.h"
#include "renderers/reference/truth_golden.h"

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
} // namespace

void register_truth_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("truth", "Render the deterministic quadrature truth of a scene and write it as a "
                                            "reference golden + JSON sidecar with its error bound");
    static std::string scene = "roughness_sweep", env, out;
    static std::vector<std::string> sets;
    static bool force = false;
    static int frames = 0;
    cmd->add_option("--scene", scene, "Scene name (iblcheck list)")->capture_default_str();
    cmd->add_option("--env", env, "Environment: a spec (iblcheck list) or a path to your own .exr/.hdr")->required();
    cmd->add_option("--out", out,
                    "Golden EXR to write (default: <reference key>.exr in the current folder); the "
                    "sidecar is the same path with .json");
    cmd->add_option("--set", sets,
                    "Option key=value (repeatable): material options, env_rotation, threads, "
                    "truth_tolerance (the coarser level's pixel tolerance)");
    cmd->add_option("--frames", frames,
                    "Render the temporal truth: frames 0..N-1 (option frame) stacked vertically "
                    "in one golden, as the temporal suite reads it (reference/<key>__frames=N.exr)");
    cmd->add_flag("--force", force, "Overwrite existing output files");
    cmd->callback([&exit_code] {
        truth::GoldenRequest req;
        req.spec.method = "reference";
        req.spec.scene = scene;
        req.spec.env = env;
        for (auto& s : sets) req.spec.options.set_from_string(s);
        namespace fs = std::filesystem;
        // The file name from the golden store's key, with the environment as recorded (a path: its name).
        TestSpec keyed = req.spec;
        keyed.env = truth::portable_env_spec(env);
        req.out_exr =
            out.empty() ? reference_key(keyed) + (frames > 0 ? "__frames=" + std::to_string(frames) : "") + ".exr" : out;
        const fs::path json = fs::path(req.out_exr).replace_extension(".json");
        if (!force)
            for (const fs::path& p : {fs::path(req.out_exr), json})
                if (fs::exists(p)) throw UsageError(p.string() + ": exists; pass --force to overwrite");
        // The regenerating command as recorded: no absolute paths (a file environment by its name).
        req.command = fmt::format("iblcheck truth --scene {} --env {}", scene, keyed.env);
        for (auto& s : sets) req.command += " --set " + s;
        ProgressLine line(scene + " / " + keyed.env);
        req.progress = [&line](double f) { line(f); };
        if (frames > 0) {
            truth::SequenceRequest sr;
            sr.spec = req.spec, sr.frames = frames, sr.bound_frames = {0, frames / 2}, sr.out_exr = req.out_exr;
            sr.command = req.command + " --frames " + std::to_string(frames);
            sr.progress = req.progress;
            const nlohmann::json m = truth::write_truth_sequence_golden(sr);
            line.done();
            const auto& b = m["error_bound"];
            fmt::print("wrote {} and {} ({} frames of {}x{}, {:.1f} s)\n", req.out_exr, json.string(), frames,
                       m["width"].get<int>(), m["height"].get<int>(), m["time_s"].get<double>());
            fmt::print("error bound (frames {} and {} against the finer level): relative RMSE <= {:.4f} %, mean FLIP <= {:.5f}, "
                       "LDR FLIP <= {:.5f}\n",
                       sr.bound_frames[0], sr.bound_frames[1], 100 * b["relative_rmse_max"].get<double>(),
                       b["mean_flip_max"].get<double>(), b["mean_flip_ldr_max"].get<double>());
            exit_code = kExitPass;
            return;
        }
        const truth::GoldenWritten g = truth::write_truth_golden(req);
        line.done();
        const auto& b = g.meta["error_bound"];
        fmt::print("wrote {} and {} ({}x{}, {:.1f} s)\n", req.out_exr, json.string(), g.meta["width"].get<int>(),
                   g.meta["height"].get<int>(), g.meta["time_s"].get<double>());
        fmt::print("error bound (coarser vs finer level): relative RMSE {:.4f} %, mean FLIP {:.5f}, worst pixel {:.4f} "
                   "({:.2f} % relative) -> criterion {}\n",
                   100 * b["relative_rmse"].get<double>(), g.mean_flip, b["worst_pixel"].get<double>(),
                   100 * b["worst_pixel_relative"].get<double>(), g.criterion_met ? "met" : "NOT met");
        for (const auto& s : b["per_sphere"])
            fmt::print("  {:<16} relative RMSE {:.4f} %  mean FLIP {:.5f}  worst pixel {:.4f}\n", s["label"].get<std::string>(),
                       100 * s["relative_rmse"].get<double>(), s["mean_flip"].get<double>(), s["worst_pixel"].get<double>());
        exit_code = g.criterion_met ? kExitPass : kExitRegression;
    });
}

} // namespace iblcheck::cli
