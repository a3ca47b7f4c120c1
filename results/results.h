// The results of a run (schema iblcheck-results/1, results/RESULTS_FORMAT.md) as types: a check, a
// comparison, a test and the run. The harness fills them and writes them with to_json (results.json
// is their JSON); from_json reads them back. Each object lists its keys once, with their JSON types
// (fields()): the reader's validation (results_file.h) checks types from that list, and a test
// (tests/test_results.cpp) holds RESULTS_FORMAT.md's key tables and to_json's output to it.
//
// The figures groups a report reads but the harness measures elsewhere stay JSON inside the types
// (metrics, images, temporal, stability, furnace, provenance, profile, layout): their producers own
// their shape.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "kernel/json_check.h"

namespace iblcheck {

// Ordered by severity: overall_verdict() (harness/verdict.h) keeps the worst.
enum class Verdict { pass, improved, fail, missing_golden, error };

std::string_view verdict_name(Verdict v);     // "pass", "improved", "fail", "missing-golden", "error"
Verdict parse_verdict(std::string_view name); // throws InputError on an unknown name

// One tolerance of a comparison: the value, the interval it had to lie in, and what it gave.
struct Check {
    std::string metric; // "flip.mean", "accuracy.flip.mean", "cost.spirv_instructions_per_pixel"
    double value = 0;
    std::optional<double> min, max; // the interval the value had to lie in
    std::optional<double> approved; // bands and costs: the approved figure the interval is built on
    Verdict status = Verdict::pass; // pass, improved or fail
    std::string message;            // empty on pass
};

// The worst 16x16 block of a comparison and the sphere it lies on.
struct WorstBlock {
    int x = 0, y = 0;
    double flip = 0;    // its mean FLIP
    std::string metric; // the map it was found in: "flip" or "display_flip"
    std::string sphere; // "" when the block's centre shows no sphere
};

// One comparison of the render against one golden (or, kind "cost", of its cost per pixel).
struct Comparison {
    std::string kind;       // "baseline", "reference" or "cost"
    std::string golden;     // path relative to the golden root
    std::string label;      // baseline@label, "" for the primary (written for baselines only)
    nlohmann::json metrics; // compare_images() output; null when the sizes differ
    std::vector<Check> checks;
    Verdict verdict = Verdict::pass;
    std::string message;                   // the failing checks, joined
    nlohmann::json images;                 // report images (test/golden/heatmap), set by the runner
    std::optional<WorstBlock> worst_block; // set by the runner
    nlohmann::json approved;               // baselines: facts of the golden's sidecar (null: not written)
};

// One pass of a render and its wall time.
struct Timing {
    std::string pass;
    double ms = 0;
    bool gpu = false, precompute = false;
};

// What a render gave, before it is judged (absent from a test whose render failed).
struct RenderFigures {
    int width = 0, height = 0;
    std::vector<Timing> timings;
    double precompute_ms = 0;
    double frame_ms = 0;                  // the median of frame_ms_samples when timings are repeated
    std::vector<double> frame_ms_samples; // sorted; empty (not written) without repeats
    // The tests whose renders the samples pool (harness/timing_groups.h): this test's name with the
    // environment as "*"; empty (not written) when they are the test's own.
    std::string timing_group;
    double texture_fetches_per_pixel = 0;
    std::optional<uint64_t> texture_bytes, texel_count; // the sampled environment texture, when there is one
    nlohmann::json cost;                                // {texture_fetches_per_pixel, spirv_instructions_per_pixel}
    nlohmann::json provenance;
};

// The test's accuracy against its truth, linear HDR (and, for a display test, after the display).
struct DisplayAccuracy {
    nlohmann::json space; // the display space (metrics/display_space.h)
    double flip_mean = 0, ssim = 0, psnr_db = 0;
};
struct Accuracy {
    double flip_mean = 0;
    double ssim = 0;
    std::string golden;
    nlohmann::json noise_floor; // the reference golden's seed noise (null when it records none)
    std::optional<DisplayAccuracy> display;
};

// One test of a run: what it is, what its render gave, every comparison, the verdict and why.
struct TestResult {
    std::string name, suite, scene, method, env;
    nlohmann::json options; // {key: plain value}, the --set spelling
    std::string variant;
    nlohmann::json display; // the display space it is also scored in; null: linear HDR only
    std::vector<std::string> tags;
    std::string bless_command;
    std::optional<RenderFigures> render; // written flat into the test object
    std::optional<std::string> image, image_exr;
    std::optional<nlohmann::json> layout; // may be null (more spheres than the id map holds)
    std::vector<Comparison> comparisons;
    std::optional<Accuracy> accuracy;           // written as null when absent
    std::optional<std::string> driver_mismatch; // written as null when absent
    nlohmann::json per_sphere;                  // null: not written
    std::optional<nlohmann::json> furnace, temporal, stability;
    Verdict verdict = Verdict::pass;
    std::string message;
    std::optional<double> wall_s;
    std::optional<nlohmann::json> profile;
};

// The run: its facts and every test; counts are recounted from the tests when written.
struct RunResults {
    std::string suite, command, started;
    double total_s = 0;
    std::string commit;
    bool dirty = false;
    nlohmann::json driver;       // {device, driver, driver_info, mesa, llvm, api}
    nlohmann::json cpu_features; // this machine's, as the provenance records them
    std::string cpu_class;
    std::string shard; // "i/n"
    std::vector<TestResult> tests;
};

inline constexpr const char* kResultsSchema = "iblcheck-results/1";

nlohmann::json to_json(const Check& c);
nlohmann::json to_json(const Comparison& c);
nlohmann::json to_json(const TestResult& t);
nlohmann::json to_json(const RunResults& r);
// Read back (j.get<TestResult>()): a missing key reads as its default (NaN for a number), null as
// absent; a verdict that is not one throws InputError.
void from_json(const nlohmann::json& j, Check& c);
void from_json(const nlohmann::json& j, Comparison& c);
void from_json(const nlohmann::json& j, TestResult& t);
void from_json(const nlohmann::json& j, RunResults& r);

// The number of tests per verdict ({"pass": n, ..., "error": n}): the results' "counts".
nlohmann::json count_verdicts(const std::vector<TestResult>& tests);

// One key of a results object: its JSON type, whether a results file must have it, and whether the
// reader checks its type (a key the report reads; the others it ignores).
struct Field {
    const char* key;
    JsonType type;
    bool required = false;
    bool checked = false;
};
enum class ResultsObject { run, test, comparison, check };
// The keys of an object, in the order RESULTS_FORMAT.md's tables list them.
const std::vector<Field>& fields(ResultsObject object);

} // namespace iblcheck
