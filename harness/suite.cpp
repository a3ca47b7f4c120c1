#include "suite.h"

#include "kernel/name_filter.h"

#include <fnmatch.h>

#include <fmt/core.h>

#include <cmath>

#include <fstream>
#include <regex>
#include <set>

#include "harness/golden_store.h"
#include "kernel/errors.h"
#include "kernel/json_check.h"
#include "metrics/catalog.h"
#include "renderers/environments/environment.h"
#include "renderers/option_table.h"
#include "renderers/renderer.h"
#include "renderers/vulkan/shader_compiler.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// The keys tolerances and bands may name: the catalog's judged metrics.
const std::set<std::string> kMetrics = judged_metric_keys();

// The suite reader's checks: the shared ones (kernel/json_check.h) plus options and bounds.
struct Ctx : JsonChecker {
    using JsonChecker::JsonChecker;
    // Option values are written as strings or numbers; both become the CLI's text form.
    std::string option_value(const json& j, const std::string& where) const {
        if (j.is_string()) return j.get<std::string>();
        if (j.is_number_unsigned()) return std::to_string(j.get<unsigned long long>()); // above 2^63: not wrapped
        if (j.is_number_integer()) return std::to_string(j.get<long long>());
        if (j.is_number()) {
            std::string s = json(j.get<double>()).dump();
            return s;
        }
        if (j.is_boolean()) return j.get<bool>() ? "1" : "0";
        fail(where, "must be a string or a number");
    }
    // A count: a whole number in lo..hi (a double such as 1e300 would not fit an int).
    int integer(const json& j, const std::string& where, int lo, int hi) const {
        const double v = num(j, where);
        if (!(v >= lo && v <= hi && v == std::floor(v)))
            fail(where, "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ", not " + j.dump());
        return int(v);
    }
    OptionMap options(const json& j, const std::string& where) const {
        if (!j.is_object()) fail(where, "must be an object of option: value");
        OptionMap m;
        for (auto& [k, v] : j.items()) m.set(k, option_value(v, where + "." + k));
        return m;
    }
    std::map<std::string, Bound> bounds(const json& j, const std::string& where) const {
        std::map<std::string, Bound> out;
        keys(j, where, kMetrics);
        for (auto& [metric, b] : j.items()) {
            std::string w = where + "." + metric;
            if (b.is_null()) { // null drops a suite default: the metric is not checked for this test
                out[metric] = Bound{};
                continue;
            }
            keys(b, w, {"min", "max"});
            Bound bound;
            if (b.contains("min")) bound.min = num(b["min"], w + ".min");
            if (b.contains("max")) bound.max = num(b["max"], w + ".max");
            if (!bound.min && !bound.max) fail(w, "needs min or max");
            out[metric] = bound;
        }
        return out;
    }
    std::map<std::string, Band> bands(const json& j, const std::string& where) const {
        std::map<std::string, Band> out;
        keys(j, where, kMetrics);
        for (auto& [metric, b] : j.items()) {
            std::string w = where + "." + metric;
            keys(b, w, {"below", "above", "abs"});
            Band band;
            if (b.contains("below")) band.below = num(b["below"], w + ".below");
            if (b.contains("above")) band.above = num(b["above"], w + ".above");
            if (b.contains("abs")) band.abs = num(b["abs"], w + ".abs");
            if (band.below < 0 || band.above < 0 || band.abs < 0) fail(w, "band widths must be >= 0");
            out[metric] = band;
        }
        return out;
    }
};

StabilitySpec parse_stability(const Ctx& c, const json& j, const std::string& where, StabilitySpec st) {
    c.keys(j, where,
           {"repeats", "seeds", "thread_counts", "roughness_bias", "camera_shift", "min_margin", "fail_on_flaky", "cpu_caps"});
    st.enabled = true;
    if (j.contains("repeats")) st.repeats = c.integer(j["repeats"], where + ".repeats", 1, 1000);
    if (j.contains("seeds")) st.seeds = c.integer(j["seeds"], where + ".seeds", 1, 1000);
    if (j.contains("thread_counts")) st.thread_counts = c.boolean(j["thread_counts"], where + ".thread_counts");
    if (j.contains("roughness_bias")) st.roughness_bias = c.num(j["roughness_bias"], where + ".roughness_bias");
    if (j.contains("camera_shift")) st.camera_shift = c.num(j["camera_shift"], where + ".camera_shift");
    if (j.contains("min_margin")) st.min_margin = c.num(j["min_margin"], where + ".min_margin");
    if (j.contains("fail_on_flaky")) st.fail_on_flaky = c.boolean(j["fail_on_flaky"], where + ".fail_on_flaky");
    if (j.contains("cpu_caps")) {
        const json& caps = j["cpu_caps"];
        if (!caps.is_array()) c.fail(where + ".cpu_caps", "must be an array of GALLIUM_OVERRIDE_CPU_CAPS values");
        st.cpu_caps.clear();
        for (size_t k = 0; k < caps.size(); ++k) {
            std::string v = c.str(caps[k], where + ".cpu_caps[" + std::to_string(k) + "]");
            // The values Mesa 22.3 recognises (u_cpu_detect.c); others are silently ignored by Mesa.
            static const std::set<std::string> known = {"nosse", "sse", "sse2", "sse3", "ssse3", "sse4.1", "avx"};
            if (!known.count(v))
                c.fail(where + ".cpu_caps[" + std::to_string(k) + "]",
                       "'" + v + "' is not one of nosse, sse, sse2, sse3, ssse3, sse4.1, avx (Mesa ignores other values)");
            st.cpu_caps.push_back(v);
        }
    }
    if (st.repeats < 1 || st.seeds < 1) c.fail(where, "repeats and seeds must be >= 1");
    return st;
}

// "display": the space a player sees (metrics/display_space.h). Every field is checked here, so
// a misspelt tonemapper or an exposure of "NaN" is an error naming the suite file and the field.
DisplaySpace parse_display(const Ctx& c, const json& j, const std::string& where) {
    c.keys(j, where, {"tonemap", "exposure", "quantize", "target"});
    if (!j.contains("tonemap")) c.fail(where + ".tonemap", "missing required key (aces_narkowicz or pbr_neutral)");
    DisplaySpace d;
    const std::string tm = c.str(j["tonemap"], where + ".tonemap");
    if (auto t = parse_tonemap(tm))
        d.tonemap = *t;
    else
        c.fail(where + ".tonemap", "unknown tonemapper '" + tm +
                                       "'; valid: aces_narkowicz (Narkowicz's ACES fit, HDR-FLIP's curve), pbr_neutral "
                                       "(Khronos PBR Neutral)");
    if (j.contains("exposure")) {
        d.exposure_ev = c.num(j["exposure"], where + ".exposure");
        if (!(std::fabs(d.exposure_ev) <= kMaxDisplayExposure))
            c.fail(where + ".exposure",
                   fmt::format("must be a finite number of stops within ±{}, not {}", kMaxDisplayExposure, j["exposure"].dump()));
    }
    if (j.contains("quantize")) {
        const std::string q = c.str(j["quantize"], where + ".quantize");
        if (auto v = parse_quantize(q))
            d.quantize = *v;
        else
            c.fail(where + ".quantize", "unknown quantisation '" + q + "'; valid: srgb8, none");
    }
    if (j.contains("target")) {
        const std::string t = c.str(j["target"], where + ".target");
        if (auto v = parse_target(t))
            d.target = *v;
        else
            c.fail(where + ".target", "unknown render target '" + t + "'; valid: rgba32f, rgba16f, r11g11b10f");
    }
    return d;
}

void parse_size(const Ctx& c, const json& j, const std::string& where, int& w, int& h) {
    std::string s = c.str(j, where);
    if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 8192 || h > 8192)
        c.fail(where, "'" + s + "' is not WxH");
}

// One environment of a suite: a spec (built-in, or a file path) or {"file": PATH, "name": NAME}. A
// relative file path is the suite file's neighbour (the suite and its HDRIs move together); the test
// names and golden keys use its stable name (environment_label), never the path.
struct EnvEntry {
    std::string spec, name;
};
EnvEntry parse_env(const Ctx& c, const json& j, const std::string& where, const fs::path& suite_file) {
    EnvEntry e;
    if (j.is_object()) {
        c.keys(j, where, {"file", "name"});
        if (!j.contains("file")) c.fail(where + ".file", "missing required key");
        e.spec = c.str(j["file"], where + ".file");
        if (j.contains("name")) e.name = c.str(j["name"], where + ".name");
        if (!is_environment_file(e.spec)) c.fail(where + ".file", "'" + e.spec + "' is a built-in environment, not a file");
    } else {
        e.spec = c.str(j, where);
    }
    if (is_environment_file(e.spec) && fs::path(e.spec).is_relative())
        e.spec = (fs::absolute(suite_file).parent_path() / e.spec).lexically_normal().string();
    // The name is a file name and a glob-free test-name part; a built-in's name would take its goldens.
    static const std::regex ok("[A-Za-z0-9._-]+");
    if (j.is_object() && j.contains("name") && (!std::regex_match(e.name, ok) || !is_environment_file(e.name)))
        c.fail(where + ".name", "'" + e.name + "' must be one or more of A-Z a-z 0-9 . _ - and not a built-in environment");
    return e;
}

} // namespace

TestSpec without_specular_aa(TestSpec spec) {
    spec.options.set("specular_aa", "off");
    spec.options.erase("specular_aa_variance");
    spec.options.erase("specular_aa_threshold");
    return spec;
}

TestSpec temporal_reference_spec(const TestCase& tc) {
    TestSpec ref = without_specular_aa(tc.spec);
    ref.options.set("ssaa", std::to_string(tc.temporal.reference_ssaa * ssaa_of(tc.spec.options)));
    for (const auto& [k, v] : tc.temporal.reference_options.values()) ref.options.set(k, v);
    return ref;
}

fs::path suite_dir() {
    if (const char* e = std::getenv("IBLCHECK_SUITE_DIR"); e && *e) return e;
    return fs::path(IBLCHECK_SOURCE_DIR) / "harness" / "suites";
}

std::vector<std::string> suite_names() {
    std::vector<std::string> out;
    if (fs::is_directory(suite_dir()))
        for (auto& e : fs::directory_iterator(suite_dir()))
            if (e.path().extension() == ".json") out.push_back(e.path().stem().string());
    std::sort(out.begin(), out.end());
    return out;
}

// Several globs separated by '|' match a name when one of them does (the "approve all failures"
// line names each failing test). A '|' after a backslash is part of its glob: a test name (an
// environment file's name) may hold one, and glob_escape writes it so.
bool glob_match(const std::string& pattern, const std::string& name) { return name_filter_match(pattern, name); }

namespace {

// What the suite's "defaults" give every test.
struct SuiteDefaults {
    double max_cost_growth = 0.25;
    StabilitySpec stability;
    EnvEntry env{"studio", ""};
    int width = 0, height = 0;
    std::map<std::string, Bound> bounds;
    std::map<std::string, Band> bands;
    std::optional<DisplaySpace> display;
    std::string shader; // absolute; the mobile tests' (suite.h)
};

// A "shader" path, relative to the suite file, as an absolute path to a file that defines ibl_shade.
std::string shader_path(const Ctx& c, const json& j, const std::string& where, const fs::path& suite_file) {
    const fs::path file = (fs::absolute(suite_file).parent_path() / c.str(j, where)).lexically_normal();
    try {
        vk::check_ibl_shade_file(file);
    } catch (const InputError& e) {
        c.fail(where, e.what());
    }
    return file.string();
}

// "defaults": what every test inherits, plus the suite-wide jobs and timing_repeats.
SuiteDefaults parse_defaults(const Ctx& c, const json& defaults, Suite& suite) {
    c.keys(defaults, "defaults",
           {"env", "size", "jobs", "baseline_tolerances", "reference_band", "stability", "max_cost_growth", "timing_repeats",
            "display", "shader"});
    SuiteDefaults d;
    if (defaults.contains("display") && !defaults["display"].is_null())
        d.display = parse_display(c, defaults["display"], "defaults.display");
    if (defaults.contains("max_cost_growth")) d.max_cost_growth = c.num(defaults["max_cost_growth"], "defaults.max_cost_growth");
    if (defaults.contains("stability"))
        d.stability = parse_stability(c, defaults["stability"], "defaults.stability", d.stability);
    if (defaults.contains("env")) d.env = parse_env(c, defaults["env"], "defaults.env", suite.file);
    if (defaults.contains("shader")) d.shader = shader_path(c, defaults["shader"], "defaults.shader", suite.file);
    if (defaults.contains("size")) parse_size(c, defaults["size"], "defaults.size", d.width, d.height);
    if (defaults.contains("jobs")) suite.jobs = c.integer(defaults["jobs"], "defaults.jobs", 1, 1024);
    if (defaults.contains("timing_repeats")) {
        const double n = c.num(defaults["timing_repeats"], "defaults.timing_repeats");
        if (!(n >= 1 && n <= 20 && n == std::floor(n))) c.fail("defaults.timing_repeats", "must be an integer in 1..20");
        suite.timing_repeats = int(n);
    }
    if (defaults.contains("baseline_tolerances"))
        d.bounds = c.bounds(defaults["baseline_tolerances"], "defaults.baseline_tolerances");
    if (defaults.contains("reference_band")) d.bands = c.bands(defaults["reference_band"], "defaults.reference_band");
    return d;
}

// A test's "temporal": the frame count, the reference sequence and the checks.
TemporalSpec parse_temporal(const Ctx& c, const json& tj, const std::string& tw) {
    TemporalSpec temporal;
    c.keys(tj, tw, {"frames", "reference_ssaa", "reference_options", "checks"});
    if (!tj.contains("frames")) c.fail(tw + ".frames", "missing required key");
    temporal.frames = c.integer(tj["frames"], tw + ".frames", 2, 256);
    if (tj.contains("reference_ssaa")) temporal.reference_ssaa = c.integer(tj["reference_ssaa"], tw + ".reference_ssaa", 1, 64);
    if (tj.contains("reference_options"))
        temporal.reference_options = c.options(tj["reference_options"], tw + ".reference_options");
    if (tj.contains("checks")) {
        const json& cj = tj["checks"];
        c.keys(cj, tw + ".checks",
               {"flicker", "variation_ratio", "flip_mean", "flicker_ratio", "flip_ratio", "truth_flicker", "truth_flip_mean",
                "truth_flip_ratio"});
        for (auto& [k, b] : cj.items()) {
            std::string bw = tw + ".checks." + k;
            c.keys(b, bw, {"min", "max"});
            Bound bound;
            if (b.contains("min")) bound.min = c.num(b["min"], bw + ".min");
            if (b.contains("max")) bound.max = c.num(b["max"], bw + ".max");
            temporal.checks[k] = bound;
        }
    }
    return temporal;
}

// One entry of "tests" before expansion: what its test cases share, its environments, its options
// and its variants (each test case is one environment × one variant).
struct TestEntry {
    TestCase proto;
    std::vector<EnvEntry> envs;
    OptionMap base_opts;
    std::vector<OptionMap> variants;
};

TestEntry parse_test(const Ctx& c, const json& t, const std::string& w, const Suite& suite, const SuiteDefaults& d) {
    c.keys(t, w,
           {"scene", "method", "env", "size", "options", "variants", "baseline", "reference", "baseline_tolerances",
            "reference_band", "tags", "temporal", "stability", "max_cost_growth", "tolerance_note", "measure_only", "display",
            "shader", "timing_repeats"});
    if (t.contains("tolerance_note")) c.str(t["tolerance_note"], w + ".tolerance_note");
    if (!t.contains("scene")) c.fail(w + ".scene", "missing required key");
    if (!t.contains("method")) c.fail(w + ".method", "missing required key");
    TestEntry entry;
    if (!t.contains("env"))
        entry.envs.push_back(d.env);
    else if (t["env"].is_array())
        for (size_t k = 0; k < t["env"].size(); ++k)
            entry.envs.push_back(parse_env(c, t["env"][k], w + ".env[" + std::to_string(k) + "]", suite.file));
    else
        entry.envs.push_back(parse_env(c, t["env"], w + ".env", suite.file));
    if (t.contains("options")) entry.base_opts = c.options(t["options"], w + ".options");
    if (t.contains("variants")) {
        if (!t["variants"].is_array()) c.fail(w + ".variants", "must be an array of option objects");
        for (size_t k = 0; k < t["variants"].size(); ++k)
            entry.variants.push_back(c.options(t["variants"][k], w + ".variants[" + std::to_string(k) + "]"));
    } else {
        entry.variants.emplace_back();
    }
    TestCase& proto = entry.proto;
    proto.suite = suite.name;
    proto.suite_arg = suite.arg;
    proto.max_cost_growth =
        t.contains("max_cost_growth") ? c.num(t["max_cost_growth"], w + ".max_cost_growth") : d.max_cost_growth;
    if (!(proto.max_cost_growth >= 0)) c.fail(w + ".max_cost_growth", "must be >= 0");
    proto.spec.scene = c.str(t["scene"], w + ".scene");
    proto.spec.method = c.str(t["method"], w + ".method");
    if (t.contains("shader"))
        proto.spec.shader = shader_path(c, t["shader"], w + ".shader", suite.file);
    else if (proto.spec.method == "mobile")
        proto.spec.shader = d.shader;
    proto.spec.width = d.width;
    proto.spec.height = d.height;
    if (t.contains("size")) parse_size(c, t["size"], w + ".size", proto.spec.width, proto.spec.height);
    if (t.contains("baseline")) proto.baseline = c.boolean(t["baseline"], w + ".baseline");
    if (t.contains("reference")) proto.reference = c.boolean(t["reference"], w + ".reference");
    if (t.contains("measure_only")) proto.measure_only = c.boolean(t["measure_only"], w + ".measure_only");
    if (t.contains("timing_repeats")) proto.timing_repeats = c.integer(t["timing_repeats"], w + ".timing_repeats", 1, 20);
    proto.baseline_tolerances = d.bounds;
    if (t.contains("baseline_tolerances"))
        for (auto& [k, v] : c.bounds(t["baseline_tolerances"], w + ".baseline_tolerances")) {
            if (v.min || v.max)
                proto.baseline_tolerances[k] = v;
            else
                proto.baseline_tolerances.erase(k);
        }
    proto.reference_band = d.bands;
    if (t.contains("reference_band"))
        for (auto& [k, v] : c.bands(t["reference_band"], w + ".reference_band")) proto.reference_band[k] = v;
    if (t.contains("tags")) {
        if (!t["tags"].is_array()) c.fail(w + ".tags", std::string("must be an array of strings, not ") + t["tags"].type_name());
        for (size_t k = 0; k < t["tags"].size(); ++k)
            proto.tags.push_back(c.str(t["tags"][k], w + ".tags[" + std::to_string(k) + "]"));
    }
    proto.stability = t.contains("stability") ? parse_stability(c, t["stability"], w + ".stability", d.stability) : d.stability;
    if (t.contains("temporal")) proto.temporal = parse_temporal(c, t["temporal"], w + ".temporal");
    proto.display = d.display;
    if (t.contains("display"))
        proto.display = t["display"].is_null() ? std::nullopt : std::optional(parse_display(c, t["display"], w + ".display"));
    return entry;
}

// The test's variant: every option (not only the variant's) and a size other than the scene's own,
// so two suites testing different configurations never share a name, and so never a baseline
// golden (a suite with "size": "1x1" used to name its tests like ci's and bless over ci's goldens).
// The size goes last and only when given: the names of the suites without one are unchanged.
std::string variant_name(const TestSpec& spec) {
    std::string v = spec.options.values().empty() ? "" : spec.options.canonical();
    // A team's shading first: its tests never share a baseline with the built-in's.
    if (!spec.shader.empty()) v = "shader=" + fs::path(spec.shader).stem().string() + (v.empty() ? "" : "," + v);
    if (spec.width > 0) v += (v.empty() ? "" : ",") + fmt::format("size={}x{}", spec.width, spec.height);
    return v.empty() ? "default" : v;
}

// The entry's test cases (every environment × every variant), validated and uniquely named; two
// tests whose baselines would be the same file (names that differ only where a file name cannot,
// e.g. "a:b" and "a-b") are refused, naming both.
void expand_test(const Ctx& c, const TestEntry& entry, const std::string& w, std::map<std::string, std::string>& goldens,
                 Suite& suite) {
    for (const auto& env : entry.envs)
        for (const auto& variant : entry.variants) {
            TestCase tc = entry.proto;
            tc.spec.env = env.spec;
            tc.spec.env_name = env.name;
            tc.spec.options = entry.base_opts;
            for (auto& [k, v] : variant.values()) tc.spec.options.set(k, v);
            tc.variant = variant_name(tc.spec);
            tc.name = tc.spec.method + "." + tc.spec.scene + "." + environment_label(env.spec, env.name) + "." + tc.variant;
            if (tc.display) tc.name += ".display=" + display_label(*tc.display);
            try {
                validate_spec(tc.spec);
                if (tc.temporal.frames) validate_spec(temporal_reference_spec(tc));
            } catch (const UsageError& e) {
                c.fail(w, e.what());
            }
            const auto [it, fresh] = goldens.emplace(safe_file_name(tc.name), tc.name);
            if (!fresh && it->second == tc.name) c.fail(w, "duplicate test name " + tc.name);
            if (!fresh)
                c.fail(w, "tests " + it->second + " and " + tc.name + " would share the baseline golden " + it->first +
                              ".exr; rename an environment file or change an option so that their names differ");
            suite.tests.push_back(std::move(tc));
        }
}

// Whether a test judges its image (suite.h): a bound against its baselines, the band around the
// accuracy its baseline approved, or a temporal check. The cost alone does not.
bool judges_image(const TestCase& tc) {
    bool bound = false;
    for (const auto& [metric, b] : tc.baseline_tolerances) bound |= b.min || b.max;
    const bool temporal = tc.temporal.frames > 0 && !tc.temporal.checks.empty();
    return (tc.baseline && bound) || (tc.baseline && tc.reference && !tc.reference_band.empty()) || temporal;
}

// A display_* bound on a test without a "display" would read a figure never measured (NaN: a
// failure that says nothing about the render).
void check_display_metrics(const Ctx& c, const TestCase& tc, const std::string& w) {
    if (tc.display) return;
    for (const auto& [metric, b] : tc.baseline_tolerances)
        if (metric.rfind("display_", 0) == 0 && (b.min || b.max))
            c.fail(w + ".baseline_tolerances." + metric, tc.name + " has no \"display\" to measure it in");
    for (const auto& [metric, b] : tc.reference_band)
        if (metric.rfind("display_", 0) == 0)
            c.fail(w + ".reference_band." + metric, tc.name + " has no \"display\" to measure it in");
}

// A test that judges nothing passed whatever it rendered (issue 30); measure_only says so on purpose.
void check_judges_its_image(const Ctx& c, const TestCase& tc, const std::string& w) {
    const bool judges = judges_image(tc);
    if (!judges && !tc.measure_only)
        c.fail(w, tc.name + " judges nothing of its image (no baseline_tolerances bound with a baseline, no reference_band "
                            "with a baseline, no temporal check), so any render would pass; add one, or \"measure_only\": true "
                            "for a test that only records its figures");
    if (judges && tc.measure_only)
        c.fail(w + ".measure_only", tc.name + " judges its image; measure_only is for a test that only records its figures");
}

} // namespace

Suite load_suite(const std::string& name_or_path, const std::string& shader) {
    fs::path file = name_or_path;
    if (file.extension() != ".json") file = suite_dir() / (name_or_path + ".json");
    if (!fs::exists(file)) {
        std::string list;
        for (auto& n : suite_names()) list += (list.empty() ? "" : ", ") + n;
        throw InputError(file.string() + ": no such suite; available: " + list);
    }
    Ctx c{file.string()};
    json root = parse_json_file(file.string()); // a folder or a FIFO: refused, not read
    c.keys(root, "(top level)", {"suite", "description", "history", "defaults", "tests"});
    if (!root.contains("suite")) c.fail("suite", "missing required key");
    if (!root.contains("tests")) c.fail("tests", "missing required key");
    Suite suite;
    suite.file = file;
    // A suite found by name is named again; one given by path is given by its absolute path, so
    // the bless command printed on failure works from any folder.
    suite.arg = fs::path(name_or_path).extension() == ".json" ? fs::absolute(file).lexically_normal().string() : name_or_path;
    suite.name = c.str(root["suite"], "suite");
    if (root.contains("description")) suite.description = c.str(root["description"], "description");
    if (root.contains("history")) {
        suite.history = c.str(root["history"], "history");
        if (suite.history.empty() || fs::path(suite.history).is_absolute())
            c.fail("history", "must be a file name relative to the folder that holds --out");
    }
    SuiteDefaults defaults = parse_defaults(c, root.value("defaults", json::object()), suite);
    std::string shader_arg; // --shader: every mobile test's, over the suite's own
    if (!shader.empty()) {
        shader_arg = fs::absolute(shader).lexically_normal().string();
        vk::check_ibl_shade_file(shader_arg); // exit 2 naming the file
        defaults.shader = shader_arg;
    }

    if (!root["tests"].is_array()) c.fail("tests", "must be an array");
    std::map<std::string, std::string> goldens; // baseline file name -> the test that has it
    std::vector<std::string> where;             // each test's entry, for the check after every name is known
    for (size_t i = 0; i < root["tests"].size(); ++i) {
        const std::string w = "tests[" + std::to_string(i) + "]";
        TestEntry entry = parse_test(c, root["tests"][i], w, suite, defaults);
        if (!shader_arg.empty() && entry.proto.spec.method == "mobile") {
            entry.proto.spec.shader = shader_arg;
            entry.proto.shader_arg = shader_arg;
        }
        expand_test(c, entry, w, goldens, suite);
        where.resize(suite.tests.size(), w);
    }
    for (size_t k = 0; k < suite.tests.size(); ++k) {
        check_display_metrics(c, suite.tests[k], where[k]);
        check_judges_its_image(c, suite.tests[k], where[k]);
    }
    if (suite.tests.empty()) c.fail("tests", "the suite has no tests");
    return suite;
}

std::vector<TestCase> select_tests(const Suite& suite, const std::string& filter, int shard_index, int shard_count) {
    if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count)
        throw UsageError("--shard " + std::to_string(shard_index) + "/" + std::to_string(shard_count) +
                         ": need 0 <= index < count");
    std::vector<TestCase> out;
    size_t k = 0;
    for (const auto& t : suite.tests) {
        if (!glob_match(filter, t.name)) continue;
        if (int(k++ % size_t(shard_count)) == shard_index) out.push_back(t);
    }
    return out;
}

} // namespace iblcheck
