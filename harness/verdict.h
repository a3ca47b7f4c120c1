// Verdicts: what a test's numbers mean, decided in one place. The runner measures (render,
// metrics, cost) and hands the numbers here; nothing here renders or reads files, so every rule is
// unit-tested on plain numbers (tests/test_verdict.cpp). The results they fill (Check, Comparison,
// Verdict) are the typed results of results/results.h.
//
// One function per kind of comparison, one signature (metric, measured value, criterion) -> Check,
// after VK-GL-CTS's tcuImageCompare: a typed status and a message that says where, why and by how
// much. A NaN anywhere (value, bound, approved figure) is a failure, never a pass: every test below
// is written so that a comparison with NaN lands on the failing side.
#pragma once
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "results/results.h"

namespace iblcheck {

// A regression for CI and bisect: fail or missing-golden (exit 1). error is "cannot test" (exit 2).
bool is_regression(Verdict v);

// A fixed bound on a metric of the difference to an approved baseline.
struct Bound {
    std::optional<double> min, max;
};
// A band around a value approved at bless time: [v·(1 − below) − abs, v·(1 + above) + abs].
struct Band {
    double below = 0.1, above = 0.1, abs = 0.0;
};

// Larger is better for SSIM and PSNR; smaller for FLIP and costs.
bool higher_is_better(std::string_view metric);

// value within [min, max] passes; outside fails.
Check judge_bound(const std::string& metric, double value, const Bound& bound);
// value within the band passes; on the worse side it fails, on the better side it is `improved`.
Check judge_band(const std::string& metric, double value, double approved, const Band& band);
// A cost (work per pixel) may grow by at most `max_growth` (0.25: +25 %) over the approved cost;
// a drop by more than that is `improved` (re-bless to lock it in).
Check judge_cost(const std::string& metric, double value, double approved, double max_growth);

// The metrics JSON of one image comparison (the keys of `iblcheck compare --json`): "flip.mean" ->
// metrics["flip"]["mean"]. A missing or null metric reads as NaN (and so fails its check).
double metric_value(const nlohmann::json& metrics, const std::string& key);

// Every tolerance of a baseline comparison. Sizes must match: a size mismatch is a failed "size"
// check naming both sizes (the caller passes the sizes; metrics may then be null).
Comparison judge_baseline(const nlohmann::json& metrics, const std::map<std::string, Bound>& tolerances);
Comparison judge_size(const std::string& kind, int width, int height, int golden_width, int golden_height);
// The accuracy against the truth, checked against the band around the accuracy approved at bless
// time (approved: the baseline sidecar's "accuracy" object; a metric it lacks is not checked).
Comparison judge_reference(const nlohmann::json& metrics, const nlohmann::json& approved_accuracy,
                           const std::map<std::string, Band>& bands);

// The worst of several verdicts (pass < improved < fail < missing-golden < error).
Verdict overall_verdict(const std::vector<Verdict>& verdicts);
// Any-of-several baselines: the test passes if one approved baseline passes; otherwise the
// closest (lowest FLIP mean) failing one is reported. Returns the index of the chosen comparison.
size_t choose_baseline(const std::vector<Comparison>& candidates);

} // namespace iblcheck
