// Suites are data: harness/suites/<name>.json, one schema, validated with errors that name the
// file, the key and the problem. A suite expands into TestCases: each entry may list several
// environments and variants, and every combination is one test named
//   <method>.<scene>.<env>.<options>      (env: the environment's stable name, environment_label: a
//                                          built-in spec, or a file's "name", else its file name; options: "k=v,k=v" of all the test's options, then size=WxH when the
//                                          test gives a size; "default" when neither)
//   <method>.<scene>.<env>.<options>.display=<tonemap>_<ev>ev_<quantize>_<target>   (a test with a "display")
//
// Schema (keys marked * are required):
// {
//   "suite"*: "ci",  "description": "...",
//   "defaults": { "env": "studio", "size": "WxH", "jobs": 2, "max_cost_growth": 0.25, "timing_repeats": 1,
//                 "shader": "path/ibl_shade.glsl",
//                 "baseline_tolerances": { METRIC: {"min": x, "max": y}, ... },
//                 "reference_band": { METRIC: {"below": rel, "above": rel, "abs": a}, ... } },
//   "tests"*: [ { "scene"*: "roughness_sweep", "method"*: "mobile", "shader": "path/ibl_shade.glsl",
//                "env": "studio" | ["studio", "sky_sun"], "size": "WxH",
//                       (an environment file: "hdri/city.exr" or {"file": "hdri/city.exr", "name": "city"}; a
//                        relative path is from the suite file's folder; its content hash is in every golden's
//                        sidecar, and a changed file is an error naming it)
//                "options": {k: v}, "variants": [{k: v}, ...],
//                "baseline": true, "reference": true, "measure_only": false,
//                "display": {"tonemap"*: "aces_narkowicz" | "pbr_neutral", "exposure": 0, "quantize": "srgb8" | "none",
//                            "target": "rgba32f" | "rgba16f" | "r11g11b10f"} | null,
//                "baseline_tolerances": {...}, "reference_band": {...}, "max_cost_growth": 0.25, "tags": ["..."],
//                "tolerance_note": "why this test's tolerances differ from the defaults (measured floors)",
//                "temporal": {"frames": 32, "reference_ssaa": 8, "reference_options": {k: v},
//                             "checks": {NAME: {"min": x, "max": y}}},
//                "stability": {"repeats": 2, "seeds": 3, "thread_counts": true, "min_margin": 3,
//                              "fail_on_flaky": false, "cpu_caps": ["avx", "sse4.1"]} } ]
//                                                 ("stability" may also sit in "defaults")
// }
// METRIC is one of flip.mean, flip.p99, flip.block_max, ssim.mean, psnr.db (linear HDR: HDR-FLIP over
// exposures, SSIM and PSNR after ACES at exposure 0), or, for a test with a "display", the same figures
// where a player sees them: display_flip.mean, display_flip.p99, display_flip.block_max (LDR-FLIP),
// display_ssim.mean, display_psnr.db; in a test, METRIC: null drops a suite default (e.g. a
// percentile that seed noise alone saturates).
// "display" (metrics/display_space.h; in "defaults" or a test, whose own replaces the default's and
// null drops it) scores the test as a player sees it: the render target's rounding (default
// rgba32f: none), the exposure in EV (default 0), the tonemapper, the sRGB OETF and 8-bit
// quantisation (default srgb8). It adds ".display=<tonemap>_<ev>ev_<quantize>_<target>" to the test's
// name (its baseline's sidecar approves the display accuracy).
// baseline_tolerances bound the difference to the approved baseline (deterministic renders: tight).
// reference_band bounds the accuracy against the ground truth around the value approved at bless
// time: [v·(1 − below) − abs, v·(1 + above) + abs]; under the band is `improved`, over it `fail`.
// max_cost_growth bounds the growth of the render's deterministic cost per pixel (executed SPIR-V
// instructions, texture fetches) over the cost recorded with the baseline (0.25: +25 %).
// Every test judges its image: a baseline_tolerances bound (with "baseline": true), a reference_band
// (with a baseline, whose sidecar approved the accuracy it is built on) or a temporal check. A test
// that judges nothing would pass any render (a shader writing vec4(0) was "improved" by its cost),
// so it is an error in the suite unless it says "measure_only": true (its accuracy, cost and
// timings are recorded for the charts and the history; it fails only if it cannot render).
// shader: a team's IBL shading file (docs/SHADER_CONTRACT.md), relative to the suite file, that the
// mobile tests run instead of the built-in split sum (in "defaults": every mobile test's; a test's
// own wins). Its tests are named with shader=<file stem> first in the variant, so they have their
// own baselines; the file must exist when the suite is loaded.
// timing_repeats renders each test that many times in all (1..20): the results then hold the
// per-frame time's median and range (wall times vary 2-5x on a loaded machine; never gated). A test's
// own "timing_repeats" wins over the suite's (the nightly times its CPU reference once).
#pragma once
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "harness/verdict.h"
#include "metrics/display_space.h"
#include "renderers/render_api.h"

namespace iblcheck {

// Temporal tests (animated scenes): every frame of the test, of the same scene with
// specular_aa=off (the comparison) and of the reference sequence (the same shading, ssaa ×
// reference_ssaa, specular_aa=off: a near-perfect pixel filter) is rendered and tone-mapped;
// checks bound flicker, flip_mean and their ratios to the `off` sequence. reference_options
// override the reference's options last (e.g. shading=compute: the fragment path's tests are
// judged against the ray-traced, supersampled compute path).
struct TemporalSpec {
    int frames = 0; // 0: not a temporal test
    int reference_ssaa = 8;
    OptionMap reference_options;
    std::map<std::string, Bound> checks; // flicker, variation_ratio, flip_mean, flicker_ratio, flip_ratio
};

// Verdict stability (issue 9): determinism across repeats and lavapipe thread counts, noise floors
// (Monte Carlo methods: spread over seeds), sensitivity to tiny perturbations, and margins =
// tolerance / noise floor. A margin under min_margin is `flaky`; with fail_on_flaky it fails.
struct StabilitySpec {
    bool enabled = false;
    int repeats = 2;              // renders compared bit for bit
    int seeds = 3;                // Monte Carlo methods: seeds 0..seeds-1
    bool thread_counts = true;    // also render under LP_NUM_THREADS=1
    double roughness_bias = 1e-3; // sensitivity perturbations
    double camera_shift = 0.25;   // pixels
    double min_margin = 3.0;
    bool fail_on_flaky = false;
    // Cross-CPU noise floor: each render again with GALLIUM_OVERRIDE_CPU_CAPS=<caps> (llvmpipe then
    // generates code for that lesser CPU, as on another CI runner), in a child process.
    std::vector<std::string> cpu_caps = {"avx", "sse4.1"};
};

struct TestCase {
    std::string name;
    std::string suite;
    std::string suite_arg; // what `--suite` needs to find the suite again: its name, or its path
    std::string variant; // "default", or [shader=<stem>,] the canonical k=v list of all the test's options then size=WxH if given
    std::string shader_arg; // the `--shader FILE` given on the command line (absolute), which its bless command repeats
    TestSpec spec;
    bool baseline = true;      // compare with approved baselines
    bool reference = true;     // measure accuracy against the reference golden (which must exist)
    bool measure_only = false; // judges nothing of its image on purpose (suite.h's schema)
    std::map<std::string, Bound> baseline_tolerances;
    std::map<std::string, Band> reference_band;
    double max_cost_growth = 0.25;       // cost per pixel (SPIR-V instructions, texture fetches) vs the baseline's
    std::optional<DisplaySpace> display; // scored also as a player sees it (display_* metrics)
    std::vector<std::string> tags;
    TemporalSpec temporal;
    StabilitySpec stability;
    int timing_repeats = 0; // the test's own "timing_repeats" (0: the suite's)
};

struct Suite {
    std::string name;
    std::string description;
    std::filesystem::path file;
    std::string arg; // the suite's name, or the absolute path it was loaded from
    int jobs = 2;
    int timing_repeats = 1; // renders per test whose frame times give a median and range
    // "history": the history file a run with --out and no --history appends to, a path relative to
    // the folder that holds --out (beside the output: the History tab works for whoever runs it).
    std::string history;
    std::vector<TestCase> tests;
};

// `spec` with specular_aa=off and without the specular-AA parameters (which then select nothing),
// so that the `off` and reference sequences of every variant of a scene are the same render.
TestSpec without_specular_aa(TestSpec spec);
// The reference sequence of a temporal test: without_specular_aa(the test's spec) with ssaa ×
// reference_ssaa (renderers/option_table.h: ssaa_of), then the reference_options.
TestSpec temporal_reference_spec(const TestCase& tc);

// Folder of suite files: <source>/harness/suites (IBLCHECK_SUITE_DIR overrides).
std::filesystem::path suite_dir();
std::vector<std::string> suite_names();
// `name_or_path`: a suite name in suite_dir() or a path to a .json file. Throws InputError.
// `shader`: a team's shading file (`--shader FILE`) every mobile test runs, over the suite's own.
Suite load_suite(const std::string& name_or_path, const std::string& shader = "");
// Glob with * and ? (fnmatch semantics on the whole name); several globs separated by '|' match
// a name when one of them does and no `!GLOB` among them does (kernel/name_filter.h).
bool glob_match(const std::string& pattern, const std::string& name);
// Keeps the tests of shard `index` of `count` (round robin over the suite order).
std::vector<TestCase> select_tests(const Suite& suite, const std::string& filter, int shard_index, int shard_count);

} // namespace iblcheck
