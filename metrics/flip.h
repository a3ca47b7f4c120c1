// FLIP image-difference evaluator, LDR and HDR (Andersson et al. 2020, "FLIP: A Difference
// Evaluator for Alternating Images"; Andersson et al. 2021, "Visualizing Errors in Rendered High
// Dynamic Range Images"). Agrees per pixel with NVIDIA's reference tool (NVlabs/flip v1.6) to
// float rounding; see tests/test_metrics_flip.cpp for the measured agreement.
//
// Pipeline per LDR evaluation (stage headers under metrics/flip/):
//   linear RGB -> YCxCz (color_spaces.h) -> separable CSF filters (csf_filters.h) -> clamp in
//   linear RGB -> CIELab + Hunt -> HyAB^qc -> redistribution to [0,1]            = colour error
//   Y normalised -> separable edge/point filters (feature_detection.h) -> ^qf    = feature error
//   FLIP = colour error ^ (1 - feature error)                                     (Eq. 10)
// HDR: for each exposure in [start, stop]: expose, tone map (tone_mappers.h), clamp, LDR-FLIP;
// per-pixel maximum over exposures.
#pragma once
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "metrics/flip/flip_constants.h"
#include "metrics/flip/tone_mappers.h"

namespace iblcheck {

namespace flip {
struct Kernels;
}

struct FlipOptions {
    double ppd = double(flip::kDefaultPpd); // pixels per degree of visual angle (67.0206451)
    flip::ToneMapper tone_mapper = flip::ToneMapper::aces;
    std::optional<float> start_exposure; // HDR: computed from the reference when absent
    std::optional<float> stop_exposure;
    std::optional<int> num_exposures;       // HDR: max(2, ceil(stop - start)) when absent
    int threads = 0;                        // 0: std::thread::hardware_concurrency()
    const flip::Kernels* kernels = nullptr; // nullptr: flip::default_kernels() (flip/kernels.h)
    // HDR: bit-identical finite inputs (a render equal to its baseline, the usual pass) skip the
    // exposures' evaluation: every exposure maps both to the same colours and features, so every
    // pixel's error is 0 (issue 33: the ci suite's baseline comparisons were a fifth of its time).
    // false evaluates them anyway (tests/test_metrics_flip.cpp checks both give the same bits).
    bool skip_identical = true;
};

struct FlipResult {
    cv::Mat errmap;             // CV_32F, per-pixel FLIP error in [0,1]
    double mean = 0;            // summed in double, row order
    double weighted_median = 0; // the tool's histogram-weighted percentiles (flip/pooling.h)
    double weighted_q1 = 0;
    double weighted_q3 = 0;
    double p99 = 0; // plain 99th percentile (nearest rank)
    double min = 0, max = 0;
    double block_max = 0;         // largest mean over 16x16 blocks (edge blocks: the pixels they have)
    int block_x = 0, block_y = 0; // top-left pixel of that block
    std::string mode;             // "ldr" or "hdr"
    double ppd = 0;
    double start_exposure = 0, stop_exposure = 0; // HDR only
    int num_exposures = 0;                        // HDR only (0 for LDR)
    std::string exposure_source;                  // HDR: "reference" (the tool's rule), "test (the
                                                  // reference is black)", "none (...)" or "given"
};

// LDR-FLIP. Inputs: CV_32FC3, RGB order, sRGB-encoded values in [0,1] (values outside are
// clamped, as the tool does), same size.
FlipResult compute_flip_ldr(const cv::Mat& ref_srgb, const cv::Mat& test_srgb, const FlipOptions& opts = {});

// HDR-FLIP. Inputs: CV_32FC3, RGB order, linear radiance (non-negative), same size.
FlipResult compute_flip_hdr(const cv::Mat& ref_linear, const cv::Mat& test_linear, const FlipOptions& opts = {});

// Fills every statistic of `r` from r.errmap (mean, percentiles, min/max, 16x16 block maximum).
void pool_flip_errmap(FlipResult& r);

// The error map drawn with the magma colour map exactly as the tool does (index =
// int(v * 255 + 0.5) % 256): CV_32FC3, RGB, display values in [0,1], ready for write_png.
cv::Mat magma_heatmap(const cv::Mat& errmap);

// Exposure range HDR-FLIP would use for `ref_linear` (exposed for tests and reports).
flip::ExposureRange flip_auto_exposure_range(const cv::Mat& ref_linear, flip::ToneMapper tm);

} // namespace iblcheck
