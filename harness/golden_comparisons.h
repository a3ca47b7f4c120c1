// A render against its goldens, each comparison measured (metrics/image_compare.h) and judged (verdict.h):
// the approved baselines (any one may pass the test), the cost recorded with the chosen baseline,
// and the truth (the reference golden). Each comparison carries its report images when the test
// writes artefacts, and the worst 16x16 block with the sphere it lies on (the render's coverage).
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "artefacts.h"
#include "golden_store.h"
#include "suite.h"
#include "verdict.h"

namespace iblcheck {

struct BaselineOutcome {
    Comparison comparison;
    bool missing = false;
    Golden golden; // the baseline judged against (empty image when missing)
};

// Any of the test's approved baselines may pass it; the outcome is the one that did, or the
// closest one (missing-golden when the test has none).
BaselineOutcome judge_against_baselines(const TestCase& tc, const RenderResult& rr, const GoldenStore& store,
                                        const Artefacts& art, int flip_threads);

// The render's cost per pixel against the cost recorded with the chosen baseline, as one
// comparison of kind "cost". A baseline whose sidecar records no cost cannot gate it: an InputError
// naming the sidecar (exit 2, with the bless command), never a silent pass.
Comparison cost_comparison(const TestCase& tc, const RenderResult& rr, const BaselineOutcome& base);

// The render against its truth: the comparison, and the test's accuracy and per-sphere errors
// (the caller records them; absent when the sizes differ).
struct TruthComparison {
    Comparison comparison;
    std::optional<Accuracy> accuracy;
    nlohmann::json per_sphere; // null unless the scene has several spheres
};

// Accuracy against the reference golden `ref`, judged by the band around the baseline's approved
// accuracy.
TruthComparison judge_against_truth(const TestCase& tc, const RenderResult& rr, const Golden& ref, const GoldenStore& store,
                                    const nlohmann::json& approved_accuracy, const Artefacts& art, int flip_threads);

} // namespace iblcheck
