// The metric catalog: every figure of an image comparison that a suite may bound, a band may hold,
// a noise floor may be measured on or `iblcheck compare` prints, one entry per key, with what it
// means. The lists and rules elsewhere read it: the suite keys (harness/suite.cpp), which side of a
// band is worse (harness/verdict.cpp), the metrics stability measures (harness/stability.cpp), the
// accuracy bless approves (harness/bless.cpp), the result's accuracy summary
// (harness/golden_comparisons.cpp), the report card and the history (reports/). Adding a metric: its
// entry here, its computation (its own source file, called by compare_images in
// metrics/image_compare.cpp unless it is a part of one already computed) and its test.
#pragma once
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace iblcheck {

enum class Direction { lower_is_better, higher_is_better };

// The images a metric looks at.
enum class MetricSpace {
    linear,            // linear HDR radiance, as rendered (HDR-FLIP over its exposures)
    display_transform, // the fixed display transform of both (display_transform.h: ACES, sRGB);
                       // `compare --mode ldr`: the display values as stored
    test_display,      // a display test's own space (display_space.h): only tests with "display"
};

// Who computes it: every comparison (`run`, `bless`, `compare`), or `iblcheck compare` alone.
enum class MetricScope { judged, compare_only };

struct MetricInfo {
    const char* key;   // "flip.mean": suites, checks, noise floors, approved accuracy
    const char* group; // where compare_images() puts it: metrics[group][field]
    const char* field;
    Direction direction;
    const char* unit; // "" (a fraction in [0, 1]) or "dB"
    MetricSpace space;
    MetricScope scope;
    const char* computed_by; // the function, and the part of its result
    // Whether stability measures its noise floor (stability.h): not PSNR, whose distance between
    // two renders is no floor (+inf for identical ones).
    bool noise_floor;
    // Its name in a result's "accuracy" object against the truth (a test_display metric: in its
    // "display" object); "" when the summary leaves it out.
    const char* accuracy_name;
    // Its name in a reference golden's sidecar "noise_floor" (the truth against itself with
    // another seed, harness/truth/); "" when the sidecar has none.
    const char* truth_noise_name;
};

// Every entry, the judged ones first.
std::span<const MetricInfo> metric_catalog();
// The entry of `key`, or nullptr.
const MetricInfo* find_metric(std::string_view key);
// The entry of `key`, which must be in the catalog (a name written in the code): throws
// std::logic_error otherwise.
const MetricInfo& metric(std::string_view key);
// The keys a suite may bound (baseline_tolerances) or band (reference_band): the judged ones.
std::set<std::string> judged_metric_keys();
// The judged metrics a test's comparison gives: the linear and display_transform ones, and with
// `display` (a test with a display space) its test_display ones too.
std::vector<const MetricInfo*> judged_metrics(bool display);
// The distance a noise floor takes of a value (0 between identical images): the value itself, or
// 1 − value for a higher-is-better fraction (SSIM).
double floor_distance(const MetricInfo& m, double value);

} // namespace iblcheck
