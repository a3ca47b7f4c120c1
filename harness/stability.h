// Verdict stability of one test (suite.h, StabilitySpec): determinism (repeats in this process,
// one lavapipe thread in a child process), noise floors (Monte Carlo seeds; the CPU classes of a
// CI fleet, each render in a child process with GALLIUM_OVERRIDE_CPU_CAPS), sensitivity to tiny
// perturbations, and margins = tolerance / noise floor (a margin under min_margin is flaky).
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "suite.h"
#include "worker.h"

namespace iblcheck {

struct StabilityOutcome {
    nlohmann::json json; // the test's "stability" results object
    bool deterministic = true;
    bool flaky = false;
    std::string problem; // why it is non-deterministic or flaky ("" otherwise)
};

// `base`: the render the verdict used; `reference`: the reference golden (may be empty); `approved_accuracy`: the baseline's
// approved accuracy (bands).
StabilityOutcome run_stability(const TestCase& tc, Worker& w, const cv::Mat& base, const cv::Mat& reference,
                               const nlohmann::json& approved_accuracy, int flip_threads);

// The floor a tolerance is measured against (metrics/catalog.h's floor_distance): for FLIP metrics
// the metric of (base vs variant); for SSIM its distance from 1. Exposed for tests.
double floor_of(const nlohmann::json& metrics_base_vs_variant, const std::string& metric);

} // namespace iblcheck
