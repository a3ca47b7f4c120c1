// `iblcheck compare REF TEST`: FLIP / SSIM / PSNR between two image files.
#pragma once
#include <istream>
#include <optional>
#include <ostream>
#include <string>

namespace CLI {
class App;
}

namespace iblcheck {

struct CompareArgs {
    std::string reference, test;
    std::string metric = "all"; // flip | ssim | psnr | all
    std::string mode = "auto";  // auto (EXR/HDR -> hdr, else ldr) | ldr | hdr
    std::string heatmap;        // PNG of the FLIP error map (magma); empty: none
    std::string errmap;         // EXR of the FLIP error map; empty: none
    bool force = false;         // overwrite an existing heatmap / error map (never an input)
    bool json = false;
    double ppd = 0;                   // 0: FLIP's default 67.0206451
    std::string tone_mapper = "aces"; // HDR-FLIP: aces | hable | reinhard
    std::optional<float> start_exposure, stop_exposure;
    bool clamp_negative = false; // HDR: clamp negative radiance to 0 instead of failing
    int threads = 0;
    std::string pairs; // --pairs LIST: a file of "REF TEST" lines, "-" for stdin
};

// Runs the comparison; results go to `out` (a JSON object with --json, else a short table),
// problems to `err` as "error: <file>: <problem>". Returns 0 on success, 2 (kExitError) on bad
// input or usage.
int run_compare(const CompareArgs& args, std::ostream& out, std::ostream& err);

// One line of a --pairs list: blank (also a # comment), a pair, or malformed (problem says why).
struct PairLine {
    enum class Kind { blank, pair, bad } kind = Kind::blank;
    std::string reference, test, problem;
};
PairLine parse_pair_line(const std::string& line);

// `compare --pairs`: every pair of `list` in one process, one JSON object per line on `out` (the
// --json object plus "reference", "test", "line"; or "error" naming the file and the problem).
// Errors also go to `err`, then a summary line. Returns 0 when every pair was compared, else 2.
int run_compare_pairs(const CompareArgs& args, std::istream& list, const std::string& list_name, std::ostream& out,
                      std::ostream& err);

// Adds the `compare` subcommand; when it runs, exit_code receives run_compare's result.
void register_compare_command(CLI::App& app, int& exit_code);

} // namespace iblcheck
