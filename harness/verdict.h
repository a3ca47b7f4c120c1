// Verdicts: what a test's numbers mean, decided in one place. The runner measures (render,
// metrics, cost) and hands the numbers here; nothing here renders or reads files, so every rule is
// unit-tested on plain numbers (tests/test_verdict.cpp): the tolerances, what stops a test, the
// test's message, and the exit codes of run and bisect. The results they fill (Check, Comparison,
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

// As the metric catalog says (metrics/catalog.h, "accuracy." stripped): larger is better for SSIM
// and PSNR; smaller for FLIP, and for what it does not list (costs, temporal figures).
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

// The render's cost per pixel (`cost`: {figure: n}) against the cost its baseline approved, as one
// comparison of kind "cost" (a judge_cost check per figure). A figure the baseline does not approve
// cannot be judged: `unapproved` names it, and the caller stops the test with an error naming the
// sidecar (exit 2), never a silent pass.
struct CostJudgement {
    Comparison comparison;
    std::string unapproved;
};
CostJudgement judge_costs(const nlohmann::json& cost, const nlohmann::json& approved_cost, double max_growth);

// What stopped a test before its checks were done: NaN/Inf in the render (pixels or coverage) is the
// shader's fault, a regression (fail); a shader that does not compile, or anything else (a bad
// input, a full disk), leaves the test unjudged (error).
enum class TestStop { non_finite_render, shader_compile_error, cannot_test };
Verdict stop_verdict(TestStop stop);

// Stability (harness/stability.h): a render that is not deterministic fails; a flaky one (a
// tolerance under min_margin times its noise floor) fails only when the suite asks for it.
Verdict stability_verdict(bool deterministic, bool flaky, bool fail_on_flaky);

// The test's message: every problem, joined by "; "; the platform the baseline was blessed on too
// (driver_mismatch) when the test did not pass, as a hint, never a verdict.
std::string test_message(const std::vector<std::string>& problems, Verdict verdict,
                         const std::optional<std::string>& driver_mismatch);

// How many tests of a run got each verdict.
struct VerdictCounts {
    int pass = 0, fail = 0, improved = 0, missing = 0, error = 0;
    void add(Verdict v);
};
// `iblcheck run`: any error is 2 (cannot test), else any fail or missing-golden 1, else 0.
int run_exit_code(const VerdictCounts& counts);
// --repeat N: a verdict that changed between the runs turns a pass (0) into a regression (1).
int repeat_exit_code(int exit_code, int verdicts_changed);
// `iblcheck bisect` (git bisect run): only a verdict on the commit is 0 (good) or 1 (bad). A test
// that could not be judged (error, a shader that does not compile) or has no approved golden in
// --goldens (a goldens folder from before the test existed) is 125: skip this commit.
int bisect_exit_code(const VerdictCounts& counts, bool shader_compile_error);
// "good", "bad" or "skip (125)".
std::string_view bisect_verdict_name(int exit_code);

} // namespace iblcheck
