#include "metrics/catalog.h"

#include <stdexcept>

namespace iblcheck {

namespace {

constexpr Direction kLower = Direction::lower_is_better, kHigher = Direction::higher_is_better;
constexpr MetricSpace kLinear = MetricSpace::linear, kTransform = MetricSpace::display_transform,
                      kDisplay = MetricSpace::test_display;
constexpr MetricScope kJudged = MetricScope::judged, kCompareOnly = MetricScope::compare_only;

// key, group, field, direction, unit, space, scope, computed by, noise floor, accuracy name, truth noise name
constexpr MetricInfo kCatalog[] = {
    {"flip.mean", "flip", "mean", kLower, "", kLinear, kJudged, "compute_flip_hdr: FlipResult::mean, the mean per-pixel error",
     true, "flip_mean", "mean_flip"},
    {"flip.p99", "flip", "p99", kLower, "", kLinear, kJudged,
     "compute_flip_hdr: FlipResult::p99, the per-pixel error's 99th percentile", true, "", ""},
    {"flip.block_max", "flip", "block_max", kLower, "", kLinear, kJudged,
     "compute_flip_hdr: FlipResult::block_max, the worst 16x16 block's mean error", true, "", ""},
    {"ssim.mean", "ssim", "mean", kHigher, "", kTransform, kJudged, "compute_ssim: SsimResult::mean (null under 11x11)", true,
     "ssim", ""},
    {"psnr.db", "psnr", "db", kHigher, "dB", kTransform, kJudged, "compute_psnr: PsnrResult::db, data range 1 (999: identical)",
     false, "", ""},
    {"display_flip.mean", "display_flip", "mean", kLower, "", kDisplay, kJudged, "compute_flip_ldr: FlipResult::mean", true,
     "flip_mean", ""},
    {"display_flip.p99", "display_flip", "p99", kLower, "", kDisplay, kJudged, "compute_flip_ldr: FlipResult::p99", true, "", ""},
    {"display_flip.block_max", "display_flip", "block_max", kLower, "", kDisplay, kJudged,
     "compute_flip_ldr: FlipResult::block_max", true, "", ""},
    {"display_ssim.mean", "display_ssim", "mean", kHigher, "", kDisplay, kJudged,
     "compute_ssim: SsimResult::mean (null under 11x11)", true, "ssim", ""},
    {"display_psnr.db", "display_psnr", "db", kHigher, "dB", kDisplay, kJudged,
     "compute_psnr: PsnrResult::db, data range 1 (999: identical)", false, "psnr_db", ""},
    // `iblcheck compare` of HDR inputs also gives the PSNR of the radiance itself (data range 1,
    // so a difference above 1 counts in full): another quantity than psnr.db, so another key.
    {"linear_psnr.db", "linear_psnr", "db", kHigher, "dB", kLinear, kCompareOnly,
     "compute_psnr on the radiance: PsnrResult::db, data range 1 (999: identical)", false, "", ""},
    {"linear_psnr.relative_mse", "linear_psnr", "relative_mse", kLower, "", kLinear, kCompareOnly,
     "compute_relative_mse: mean of (t - r)^2 / (r^2 + 0.01)", false, "", ""},
};

} // namespace

std::span<const MetricInfo> metric_catalog() { return kCatalog; }

const MetricInfo* find_metric(std::string_view key) {
    for (const MetricInfo& m : kCatalog)
        if (key == m.key) return &m;
    return nullptr;
}

const MetricInfo& metric(std::string_view key) {
    if (const MetricInfo* m = find_metric(key)) return *m;
    throw std::logic_error("metric '" + std::string(key) + "' is not in the catalog (metrics/catalog.cpp)");
}

std::set<std::string> judged_metric_keys() {
    std::set<std::string> keys;
    for (const MetricInfo& m : kCatalog)
        if (m.scope == MetricScope::judged) keys.emplace(m.key);
    return keys;
}

std::vector<const MetricInfo*> judged_metrics(bool display) {
    std::vector<const MetricInfo*> out;
    for (const MetricInfo& m : kCatalog)
        if (m.scope == MetricScope::judged && (m.space != MetricSpace::test_display || display)) out.push_back(&m);
    return out;
}

double floor_distance(const MetricInfo& m, double value) {
    return m.direction == Direction::higher_is_better ? 1.0 - value : value;
}

} // namespace iblcheck
