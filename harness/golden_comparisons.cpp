#include "golden_comparisons.h"

#include <fmt/core.h>

#include <algorithm>

#include "bless.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "metrics/identical.h"
#include "metrics/image_compare.h"
#include "metrics_store.h"
#include "provenance.h"
#include "sphere_errors.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// Where the error concentrates, for a person: "worst 16x16 block at (160,16) on metal r=0.3 ...".
// Recorded on the comparison ({x, y, flip, metric, sphere}); a failing comparison's message says it
// too. The sphere is the one the render shows at the block's centre (its coverage). `metric`: the
// FLIP map it was found in, "flip" (linear HDR) or "display_flip" (LDR-FLIP on a test's display).
void note_worst_block(Comparison& c, const SphereCoverage& coverage, const FlipResult& flip, bool display) {
    const int width = coverage.ids.cols, height = coverage.ids.rows;
    std::string sphere = sphere_at(coverage, std::min(flip.block_x + 8, width - 1), std::min(flip.block_y + 8, height - 1));
    c.worst_block = WorstBlock{flip.block_x, flip.block_y, flip.block_max, display ? "display_flip" : "flip", sphere};
    if (c.verdict == Verdict::fail)
        c.message +=
            fmt::format("; worst 16x16 block at ({},{}){} with mean {} {:.4g}", flip.block_x, flip.block_y,
                        sphere.empty() ? "" : " on " + sphere, display ? "LDR-FLIP on the display" : "FLIP", flip.block_max);
}

// measure_against_golden() (metrics/image_compare.h), or what the metrics store (metrics_store.h)
// holds for the same two images, the same display and the same metric code. A render equal to its
// golden bit for bit is measured (at no cost).
json measure(const TestCase& tc, const cv::Mat& golden, const cv::Mat& image, int flip_threads, FlipResult& linear,
             FlipResult& shown) {
    ProfileStage stage("metrics"); // FLIP, SSIM, PSNR (and the display space's)
    const DisplaySpace* display = tc.display ? &*tc.display : nullptr;
    if (identical_finite(golden, image)) return measure_against_golden(golden, image, display, flip_threads, linear, shown);
    const std::string key = metrics_store_key(golden, image, display);
    if (std::optional<Measured> stored = load_measured(key)) {
        linear = std::move(stored->linear);
        shown = stored->shown ? std::move(*stored->shown) : linear;
        return std::move(stored->metrics);
    }
    Measured m;
    m.metrics = measure_against_golden(golden, image, display, flip_threads, m.linear, shown);
    if (tc.display) m.shown = shown;
    save_measured(key, m);
    linear = std::move(m.linear);
    return std::move(m.metrics);
}

// The test's accuracy against its truth: mean HDR-FLIP and SSIM, linear; a display test adds the
// same comparison as a player sees it (LDR-FLIP, SSIM and PSNR of both after the display).
Accuracy accuracy_of(const TestCase& tc, const json& metrics, const FlipResult& flip, const std::string& golden,
                     const json& noise_floor) {
    Accuracy a{flip.mean, metric_value(metrics, "ssim.mean"), golden, noise_floor, std::nullopt};
    if (tc.display)
        a.display = DisplayAccuracy{metrics.value("display", json()), metric_value(metrics, "display_flip.mean"),
                                    metric_value(metrics, "display_ssim.mean"), metric_value(metrics, "display_psnr.db")};
    return a;
}

BaselineOutcome missing_baseline(const TestCase& tc, const GoldenStore& store) {
    BaselineOutcome out;
    out.missing = true;
    out.comparison.kind = "baseline";
    out.comparison.verdict = Verdict::missing_golden;
    out.comparison.message =
        "no baseline golden at " + store.baseline_path(tc.name).string() + "; create it with: " + bless_command(tc, store);
    return out;
}

// The render against one approved baseline `g`, with its report images.
Comparison judge_against_baseline(const TestCase& tc, const RenderResult& rr, const Golden& g, const Artefacts& art,
                                  int flip_threads) {
    const cv::Mat& image = rr.image;
    if (g.image.size() != image.size()) return judge_size("baseline", image.cols, image.rows, g.image.cols, g.image.rows);
    FlipResult linear, flip;
    Comparison c = judge_baseline(measure(tc, g.image, image, flip_threads, linear, flip), tc.baseline_tolerances);
    note_worst_block(c, rr.coverage, flip, tc.display.has_value());
    if (art) {
        std::string tag = g.label.empty() ? "baseline" : "baseline@" + safe_file_name(g.label);
        // A render bit-identical to its baseline (the usual pass) shares the test's EXR.
        const bool same = bit_identical(g.image, image);
        c.images = Artefacts::images(art.rel + "test.png", art.png(tag + ".png", g.image, !same),
                                     art.heatmap(tag + "_flip.png", flip.errmap));
        if (same) c.images["golden_exr"] = c.images["test_exr"];
    }
    return c;
}

} // namespace

BaselineOutcome judge_against_baselines(const TestCase& tc, const RenderResult& rr, const GoldenStore& store,
                                        const Artefacts& art, int flip_threads) {
    std::vector<Golden> goldens = store.baselines(tc.name);
    if (goldens.empty()) return missing_baseline(tc, store);
    std::vector<Comparison> candidates;
    for (const Golden& g : goldens) {
        Comparison c = judge_against_baseline(tc, rr, g, art, flip_threads);
        c.golden = store.relative(g.image_path);
        c.label = g.label;
        candidates.push_back(std::move(c));
    }
    size_t i = choose_baseline(candidates);
    BaselineOutcome out;
    out.comparison = std::move(candidates[i]);
    out.golden = goldens[i];
    return out;
}

Comparison cost_comparison(const TestCase& tc, const RenderResult& rr, const BaselineOutcome& base) {
    CostJudgement cost = judge_costs(render_cost(rr), base.golden.provenance.value("cost", json::object()), tc.max_cost_growth);
    if (!cost.unapproved.empty())
        throw InputError(fmt::format("{}: \"cost\" has no number for \"{}\" (every baseline records the cost it approved); "
                                     "re-create it with: {}",
                                     fs::path(base.golden.image_path).replace_extension(".json").string(), cost.unapproved,
                                     bless_command(tc)));
    cost.comparison.golden = base.comparison.golden;
    return std::move(cost.comparison);
}

TruthComparison judge_against_truth(const TestCase& tc, const RenderResult& rr, const Golden& ref, const GoldenStore& store,
                                    const json& approved_accuracy, const Artefacts& art, int flip_threads) {
    const cv::Mat& image = rr.image;
    TruthComparison out;
    Comparison& c = out.comparison;
    if (ref.image.size() != image.size()) {
        c = judge_size("reference", image.cols, image.rows, ref.image.cols, ref.image.rows);
        c.golden = store.relative(ref.image_path);
        return out;
    }
    FlipResult flip, shown;
    const json metrics = measure(tc, ref.image, image, flip_threads, flip, shown);
    c = judge_reference(metrics, approved_accuracy, tc.reference_band);
    c.golden = store.relative(ref.image_path);
    note_worst_block(c, rr.coverage, shown, tc.display.has_value());
    out.accuracy = accuracy_of(tc, metrics, flip, c.golden, ref.provenance.value("noise_floor", json()));
    out.per_sphere = per_sphere_errors(rr.coverage, flip.errmap);
    if (art) {
        c.images = Artefacts::images(art.rel + "test.png", art.png("reference.png", ref.image, false),
                                     art.heatmap("reference_flip.png", shown.errmap));
        c.images["golden_exr"] = art.shared_exr(c.golden, ref.image);
    }
    return out;
}

} // namespace iblcheck
