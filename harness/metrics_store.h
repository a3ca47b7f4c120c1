// A comparison's metrics on disk (issue 33): after the renders, HDR-FLIP and SSIM of each render
// against its truth were the ci suite's largest cost (5 s of 17 s of worker time, warm), and a render
// that did not change (a run after an edit that touched other variants, a bisect step, a second run)
// gives the same figures bit for bit. An entry holds everything measure_against_golden()
// (metrics/image_compare.h) returns: the metrics JSON, the linear HDR-FLIP result with its error
// map, and a display test's LDR-FLIP result with its map. It is named by a hash of every input: both
// images' size, type and bytes, the display space (or none), this layout, and the metric code's hash
// (program.h: metrics_code_hash; a change to the renderers, the rest of the harness, the report or
// the CLI keeps it). A changed input is a miss; a damaged or truncated entry is computed again.
// Bit-identical finite pairs (a render equal to its baseline) are not stored: their metrics cost
// nothing (metrics/identical.h).
// IBLCHECK_METRICS_CACHE=0 turns it off; =DIR puts it there (default: beside the SPIR-V cache, metrics/).
#pragma once
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "kernel/program.h"
#include "metrics/display_space.h"
#include "metrics/flip.h"

namespace iblcheck {

// What one comparison measured: measure()'s result (golden_comparisons.cpp).
struct Measured {
    nlohmann::json metrics;
    FlipResult linear;               // HDR-FLIP on the radiance
    std::optional<FlipResult> shown; // a display test's LDR-FLIP on its display; none: `linear`
};

// Where entries go: $IBLCHECK_METRICS_CACHE, else <SPIR-V cache's parent>/metrics; empty when off.
std::filesystem::path metrics_store_dir();

// The entry's name for `test` against `golden` in `display` (none: linear only). `tool`: the code
// that measures (program.h).
std::string metrics_store_key(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace* display,
                              const std::string& tool = metrics_code_hash());

// The entry under `key`; none when there is none, the store is off or the entry is damaged.
std::optional<Measured> load_measured(const std::string& key);

// Stores `m` under `key` (a temporary file renamed); a failure to write is ignored (an optimisation).
void save_measured(const std::string& key, const Measured& m);

} // namespace iblcheck
