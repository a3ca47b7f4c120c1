// Metrics of a render against a golden, as results JSON (the keys `iblcheck compare --json`
// prints), and the per-sphere breakdown of an error map by the render's sphere coverage (which the
// renderer reports: renderers/scenes/coverage.h). Measures only: harness/verdict.h judges.
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "metrics/display_space.h"
#include "metrics/flip.h"
#include "renderers/render_api.h"

namespace iblcheck {

// HDR-FLIP, SSIM (on the display transform; null with "not_applicable" under 11x11) and PSNR of
// `test` against `golden` (same size, finite). `flip_out` receives the FLIP result with its map.
// With a `display` (a test scored as a player sees it: metrics/display_space.h) the metrics also hold
// the same figures in that space: "display" (the space), "display_flip" (LDR-FLIP),
// "display_ssim" and "display_psnr", judged as display_flip.mean, display_ssim.mean, display_psnr.db.
nlohmann::json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out = nullptr,
                              const DisplaySpace* display = nullptr);

// LDR-FLIP, SSIM and PSNR of both images after to_display(`display`), as the groups above.
// `flip_out` receives the LDR-FLIP result with its map.
nlohmann::json compare_in_display(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace& display, int flip_threads,
                                  FlipResult* flip_out = nullptr);

// Mean FLIP per sphere of a multi-sphere scene (null for single-sphere scenes), labelled with the
// scene's sphere names. `coverage`: the render's (RenderResult::coverage), the error map's size.
nlohmann::json per_sphere_errors(const SphereCoverage& coverage, const cv::Mat& errmap);

// Where each sphere lies in a render, for the report's "what is under the pointer": `ids` (CV_8U,
// the render's size) holds 0 for the background and i + 1 for sphere i (at most 254 spheres, else
// empty); `spheres` lists {label, roughness, metallic} in that order.
struct SphereLayout {
    cv::Mat ids;
    nlohmann::json spheres = nlohmann::json::array();
};
SphereLayout sphere_layout(const SphereCoverage& coverage);

// The sphere under pixel (x, y) of a render ("metal r=0.3"), or "" for the background.
std::string sphere_at(const SphereCoverage& coverage, int x, int y);

} // namespace iblcheck
