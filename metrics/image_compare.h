// The one comparison of two images: FLIP, SSIM and PSNR as the JSON groups `run` records and
// `iblcheck compare --json` prints, so a key (metrics/catalog.h) means the same in both. Measures
// only: harness/verdict.h judges.
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "metrics/display_space.h"
#include "metrics/flip.h"

namespace iblcheck {

// PSNR has no finite value for identical images, and JSON holds no inf: this stands for it.
inline constexpr double kPsnrIdentical = 999.0;

struct CompareOptions {
    // Linear HDR radiance (HDR-FLIP; SSIM and PSNR after display_transform()), or display values
    // as stored (`compare --mode ldr`: LDR-FLIP, SSIM and PSNR on them).
    bool hdr = true;
    FlipOptions flip_options; // ppd, tone mapper, exposures, threads
    bool want_flip = true, want_ssim = true, want_psnr = true;
    // HDR: also the PSNR of the radiance itself and its relative MSE ("linear_psnr", `compare` only).
    bool linear_psnr = false;
    // A display test's space: the same figures there too (compare_in_display()'s groups).
    const DisplaySpace* display = nullptr;
};

// The groups "flip" (flip_json()), "ssim" ({mean}; null with "not_applicable" under 11x11), "psnr"
// ({db, rmse, max_abs}) of `test` against `golden` (same size, finite), as `o` asks; with
// o.linear_psnr, "linear_psnr" ({db, rmse, max_abs, relative_mse}); with o.display, the display
// groups. `flip_out` receives the FLIP result with its map.
nlohmann::json compare_images(const cv::Mat& golden, const cv::Mat& test, const CompareOptions& o,
                              FlipResult* flip_out = nullptr);

// The harness's comparison: HDR, FLIP's defaults on `flip_threads` threads, every group. With a
// `display` (a test scored as a player sees it: metrics/display_space.h) the metrics also hold
// the same figures in that space: "display" (the space), "display_flip" (LDR-FLIP),
// "display_ssim" and "display_psnr", judged as display_flip.mean, display_ssim.mean, display_psnr.db.
nlohmann::json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out = nullptr,
                              const DisplaySpace* display = nullptr);

// LDR-FLIP, SSIM and PSNR of both images after to_display(`display`), as the groups above.
// `flip_out` receives the LDR-FLIP result with its map.
nlohmann::json compare_in_display(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace& display, int flip_threads,
                                  FlipResult* flip_out = nullptr);

// A render against a golden as a run measures it (what the metrics store holds): the linear
// comparison, and with a `display` (none: null) the same in that space beside it. `linear`
// receives the HDR-FLIP result (the accuracy and the per-sphere errors are linear figures);
// `shown`, the FLIP map that locates the difference for the worst block and the heatmap: a display
// test's LDR-FLIP on its display (what its tolerances judge), else the same HDR-FLIP.
nlohmann::json measure_against_golden(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace* display, int flip_threads,
                                      FlipResult& linear, FlipResult& shown);

} // namespace iblcheck
