#include "cli/compare_command.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "kernel/output_files.h"
#include "metrics/flip.h"
#include "metrics/image_compare.h"
#include "metrics/ssim.h"

namespace iblcheck {

namespace {

std::string lower_ext(const std::string& path) {
    const auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return "";
    std::string e = path.substr(dot + 1);
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

// "inf" for identical images (kPsnrIdentical), else the figure.
std::string db_text(const nlohmann::json& db) {
    return db.get<double>() == kPsnrIdentical ? std::string("inf") : fmt::format("{:.4f}", db.get<double>());
}

} // namespace

namespace {

// One comparison's results: the JSON object of --json, plus what the human-readable table needs.
struct PairResult {
    nlohmann::json j = nlohmann::json::object();
    FlipResult fr;
    bool hdr = false;
    size_t clamped[2] = {0, 0};
};

// The comparison `run` makes (metrics/image_compare.h), so a key means the same in both, with what
// only the command line chooses: FLIP's ppd, tone mapper and exposures, LDR inputs, and the PSNR of
// the radiance itself ("linear_psnr").
CompareOptions compare_options(const CompareArgs& a, bool hdr, flip::ToneMapper tm) {
    CompareOptions o;
    o.hdr = hdr;
    if (a.ppd > 0) o.flip_options.ppd = a.ppd;
    o.flip_options.tone_mapper = tm;
    o.flip_options.start_exposure = a.start_exposure;
    o.flip_options.stop_exposure = a.stop_exposure;
    o.flip_options.threads = a.threads;
    o.linear_psnr = true;
    return o;
}

// Reads both images, checks they can be compared, and computes the metrics `a` asks for. Writes the
// heatmap / error map when asked. Throws iblcheck::Error (or cv::Exception) naming the file.
PairResult compare_pair(const CompareArgs& a) {
    PairResult res;
    nlohmann::json& j = res.j;
    FlipResult& fr = res.fr;
    const bool want_flip = a.metric == "flip" || a.metric == "all";
    const bool want_ssim = a.metric == "ssim" || a.metric == "all";
    const bool want_psnr = a.metric == "psnr" || a.metric == "all";
    if (!want_flip && !want_ssim && !want_psnr)
        throw UsageError("--metric: '" + a.metric + "' is not one of flip, ssim, psnr, all");
    if (a.mode != "auto" && a.mode != "ldr" && a.mode != "hdr")
        throw UsageError("--mode: '" + a.mode + "' is not one of auto, ldr, hdr");
    const flip::ToneMapper tm = flip::parse_tone_mapper(a.tone_mapper);
    check_output_file(a.heatmap, "--heatmap", a.force, {a.reference, a.test});
    check_output_file(a.errmap, "--errmap", a.force, {a.reference, a.test});
    check_distinct_outputs(a.heatmap, "--heatmap", a.errmap, "--errmap");

    LoadedImage ref = read_image(a.reference);
    LoadedImage test = read_image(a.test);
    check_same_size(ref.pixels, test.pixels, a.reference, a.test);
    // Grey vs colour, or an image with alpha vs one without, is a different kind of image:
    // refuse. (Alpha itself is not scored: both files' colour is read as stored.)
    const int ch_ref = ref.file_channels <= 2 ? 1 : 3, ch_test = test.file_channels <= 2 ? 1 : 3;
    if (ch_ref != ch_test || ref.has_alpha() != test.has_alpha())
        throw InputError(
            fmt::format("{}: has {} channel(s) but {} has {}", a.test, test.file_channels, a.reference, ref.file_channels));
    if (ref.hdr != test.hdr)
        throw InputError(
            fmt::format("{}: is {} but {} is {}", a.test, test.hdr ? "HDR" : "LDR", a.reference, ref.hdr ? "HDR" : "LDR"));
    // The FLIP tool scores +Inf pixels as 0 error; a NaN/Inf is a renderer bug, not a score.
    check_finite(ref.pixels, a.reference);
    check_finite(test.pixels, a.test);

    const bool hdr =
        a.mode == "hdr" || (a.mode == "auto" && (ref.hdr || lower_ext(a.reference) == "exr" || lower_ext(a.reference) == "hdr"));
    res.hdr = hdr;
    size_t* clamped = res.clamped;
    if (hdr) {
        LoadedImage* imgs[2] = {&ref, &test};
        for (int i = 0; i < 2; ++i) {
            const size_t neg = count_negative(imgs[i]->pixels);
            if (neg == 0) continue;
            if (!a.clamp_negative)
                throw InputError(fmt::format("{}: {} negative value(s) in HDR input (radiance must be >= 0; "
                                             "use --clamp-negative to clamp them to 0)",
                                             imgs[i]->path, neg));
            clamped[i] = clamp_negative(imgs[i]->pixels);
        }
    }

    CompareOptions o = compare_options(a, hdr, tm);
    o.want_flip = want_flip, o.want_ssim = want_ssim, o.want_psnr = want_psnr;
    j = compare_images(ref.pixels, test.pixels, o, &fr);
    if (want_flip) {
        j["flip"]["ppd"] = fr.ppd;
        if (hdr) j["flip"]["tone_mapper"] = flip::tone_mapper_name(tm);
        if (!a.heatmap.empty()) write_png(a.heatmap, magma_heatmap(fr.errmap));
        if (!a.errmap.empty()) write_exr(a.errmap, fr.errmap);
    }
    if (want_ssim && j["ssim"]["mean"].is_null()) // the sizes, for the person who gave the files
        j["ssim"]["not_applicable"] = fmt::format("{}x{} is smaller than SSIM's {}x{} window", ref.pixels.cols, ref.pixels.rows,
                                                  kSsimMinSize, kSsimMinSize);
    if (clamped[0] || clamped[1]) j["clamped_negative"] = {{"reference", clamped[0]}, {"test", clamped[1]}};
    return res;
}

} // namespace

int run_compare(const CompareArgs& a, std::ostream& out, std::ostream& err) {
    try {
        const PairResult res = compare_pair(a);
        const nlohmann::json& j = res.j;
        const FlipResult& fr = res.fr;
        const bool hdr = res.hdr;
        const size_t* clamped = res.clamped;
        const bool want_flip = j.contains("flip"), want_ssim = j.contains("ssim"), want_psnr = j.contains("psnr");
        const flip::ToneMapper tm = flip::parse_tone_mapper(a.tone_mapper);
        if (a.json) {
            out << j.dump(2) << "\n";
        } else {
            out << fmt::format("reference: {}\ntest:      {}\nmode:      {}\n", a.reference, a.test, hdr ? "hdr" : "ldr");
            if (clamped[0] || clamped[1])
                out << fmt::format("clamped negative values: reference {}, test {}\n", clamped[0], clamped[1]);
            if (want_flip) {
                out << fmt::format("FLIP mean {:.6f}  weighted median {:.6f}  (q1 {:.6f}, q3 {:.6f})  "
                                   "p99 {:.6f}  max {:.6f}\n",
                                   fr.mean, fr.weighted_median, fr.weighted_q1, fr.weighted_q3, fr.p99, fr.max);
                out << fmt::format("FLIP worst 16x16 block: mean {:.6f} at x={}, y={}\n", fr.block_max, fr.block_x, fr.block_y);
                if (hdr)
                    out << fmt::format("HDR-FLIP exposures: {:.4f} to {:.4f}, {} exposures ({}), range from {}\n",
                                       fr.start_exposure, fr.stop_exposure, fr.num_exposures, flip::tone_mapper_name(tm),
                                       fr.exposure_source);
            }
            if (want_ssim)
                out << (j["ssim"]["mean"].is_null()
                            ? "SSIM not applicable: " + j["ssim"]["not_applicable"].get<std::string>() + "\n"
                            : fmt::format("SSIM {:.6f}\n", j["ssim"]["mean"].get<double>()));
            if (want_psnr) {
                const auto& p = j["psnr"];
                out << fmt::format("PSNR {} dB  RMSE {:.6f}  max |diff| {:.6f}{}\n", db_text(p["db"]), p["rmse"].get<double>(),
                                   p["max_abs"].get<double>(), hdr ? "  (after the display transform, as `run`)" : "");
            }
            if (want_psnr && hdr) {
                const auto& p = j["linear_psnr"];
                out << fmt::format("linear PSNR {} dB  RMSE {:.6f}  max |diff| {:.6f}  relative MSE {:.6f}  (the radiance)\n",
                                   db_text(p["db"]), p["rmse"].get<double>(), p["max_abs"].get<double>(),
                                   p["relative_mse"].get<double>());
            }
        }
        return kExitPass;
    } catch (const Error& e) {
        err << "error: " << e.what() << "\n";
        return kExitError;
    } catch (const cv::Exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitError;
    }
}

PairLine parse_pair_line(const std::string& line) {
    PairLine p;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') return p; // blank or comment
    std::string body = line.substr(first);
    while (!body.empty() && (body.back() == '\r' || body.back() == ' ' || body.back() == '\t')) body.pop_back();
    std::vector<std::string> fields;
    if (body.find('\t') != std::string::npos) {
        // Tab-separated: paths may hold spaces.
        size_t start = 0;
        for (size_t tab; (tab = body.find('\t', start)) != std::string::npos; start = tab + 1)
            if (tab > start) fields.push_back(body.substr(start, tab - start));
        if (start < body.size()) fields.push_back(body.substr(start));
    } else {
        std::istringstream ss(body);
        for (std::string f; ss >> f;) fields.push_back(f);
    }
    if (fields.size() != 2) {
        p.kind = PairLine::Kind::bad;
        p.problem = fmt::format("expected 2 paths (REF TEST), found {}", fields.size());
        return p;
    }
    p.kind = PairLine::Kind::pair;
    p.reference = fields[0];
    p.test = fields[1];
    return p;
}

int run_compare_pairs(const CompareArgs& a, std::istream& list, const std::string& list_name, std::ostream& out,
                      std::ostream& err) {
    // Options that hold for every pair are checked once, before the first image is read.
    try {
        if (a.metric != "flip" && a.metric != "ssim" && a.metric != "psnr" && a.metric != "all")
            throw UsageError("--metric: '" + a.metric + "' is not one of flip, ssim, psnr, all");
        if (a.mode != "auto" && a.mode != "ldr" && a.mode != "hdr")
            throw UsageError("--mode: '" + a.mode + "' is not one of auto, ldr, hdr");
        flip::parse_tone_mapper(a.tone_mapper);
        if (!a.heatmap.empty() || !a.errmap.empty())
            throw UsageError("--heatmap and --errmap write one pair's error map: not with --pairs");
    } catch (const Error& e) {
        err << "error: " << e.what() << "\n";
        return kExitError;
    }
    int compared = 0, failed = 0, line_no = 0;
    for (std::string line; std::getline(list, line);) {
        ++line_no;
        const PairLine p = parse_pair_line(line);
        if (p.kind == PairLine::Kind::blank) continue;
        nlohmann::json j;
        if (p.kind == PairLine::Kind::bad) {
            j = {
                {"list", list_name}, {"line", line_no}, {"error", fmt::format("{}: line {}: {}", list_name, line_no, p.problem)}};
        } else {
            CompareArgs one = a;
            one.reference = p.reference;
            one.test = p.test;
            try {
                j = compare_pair(one).j;
            } catch (const Error& e) {
                j = {{"error", e.what()}};
            } catch (const cv::Exception& e) {
                j = {{"error", e.what()}};
            }
            j["reference"] = p.reference;
            j["test"] = p.test;
            j["line"] = line_no;
        }
        if (j.contains("error")) {
            ++failed;
            err << "error: " << j["error"].get<std::string>() << "\n";
        } else {
            ++compared;
        }
        out << j.dump() << "\n" << std::flush; // a line per pair as soon as it is done (pipelines)
    }
    if (list.bad()) {
        err << "error: " << list_name << ": read failed after line " << line_no << "\n";
        return kExitError;
    }
    err << fmt::format("compared {} pair(s){}\n", compared,
                       failed ? fmt::format(", {} could not be compared", failed) : std::string());
    return failed ? kExitError : kExitPass;
}

void register_compare_command(CLI::App& app, int& exit_code) {
    auto args = std::make_shared<CompareArgs>();
    auto* sub = app.add_subcommand("compare", "Compare two images with FLIP, SSIM and PSNR");
    sub->add_option("REF", args->reference, "Reference image (EXR/HDR linear, PNG/JPG sRGB)");
    sub->add_option("TEST", args->test, "Test image");
    sub->add_option("--pairs", args->pairs,
                    "File of 'REF TEST' lines ('-': stdin; a tab between the paths allows spaces in them): "
                    "compare every pair, one JSON object per line; exit 2 if any pair could not be compared");
    sub->add_option("--metric", args->metric, "flip|ssim|psnr|all")->check(CLI::IsMember({"flip", "ssim", "psnr", "all"}));
    sub->add_option("--mode", args->mode, "auto|ldr|hdr (auto: EXR/HDR -> hdr)")->check(CLI::IsMember({"auto", "ldr", "hdr"}));
    sub->add_option("--heatmap", args->heatmap, "Write the FLIP error map as a magma PNG");
    sub->add_option("--errmap", args->errmap, "Write the FLIP error map as a float EXR");
    sub->add_flag("--force", args->force, "Overwrite an existing --heatmap/--errmap file (never REF or TEST)");
    sub->add_flag("--json", args->json, "Print one JSON object");
    sub->add_option("--ppd", args->ppd, "Pixels per degree (default 67.0206451)")->check(CLI::PositiveNumber);
    sub->add_option("--tone-mapper", args->tone_mapper, "HDR-FLIP tone mapper: aces|hable|reinhard")
        ->check(CLI::IsMember({"aces", "hable", "reinhard"}));
    sub->add_option("--start-exposure", args->start_exposure, "HDR-FLIP start exposure (stops)");
    sub->add_option("--stop-exposure", args->stop_exposure, "HDR-FLIP stop exposure (stops)");
    sub->add_flag("--clamp-negative", args->clamp_negative,
                  "Clamp negative HDR values to 0 (and report how many) instead of failing");
    sub->add_option("--threads", args->threads, "Worker threads (0: all cores)");
    sub->callback([args, &exit_code] {
        if (args->pairs.empty()) {
            if (args->reference.empty() || args->test.empty())
                throw UsageError("compare: REF and TEST are required (or --pairs LIST)");
            exit_code = run_compare(*args, std::cout, std::cerr);
            return;
        }
        if (!args->reference.empty() || !args->test.empty()) throw UsageError("compare: give REF TEST or --pairs LIST, not both");
        if (args->pairs == "-") {
            exit_code = run_compare_pairs(*args, std::cin, "stdin", std::cout, std::cerr);
            return;
        }
        std::ifstream list = open_input_file(args->pairs);
        exit_code = run_compare_pairs(*args, list, args->pairs, std::cout, std::cerr);
    });
}

} // namespace iblcheck
