#include "one_test.h"

#include <fmt/core.h>

#include <chrono>

#include "artefacts.h"
#include "bless.h"
#include "furnace_figure.h"
#include "golden_comparisons.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "provenance.h"
#include "renderers/environments/environment.h"
#include "stability.h"
#include "temporal_check.h"
#include "timing_groups.h"
#include "verdict.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// What the test is, before anything is rendered.
TestResult test_header(const TestCase& tc, const GoldenStore& store) {
    TestResult r;
    r.name = tc.name;
    r.suite = tc.suite;
    r.scene = tc.spec.scene;
    r.method = tc.spec.method;
    r.env = environment_label(tc.spec.env, tc.spec.env_name);
    r.options = tc.spec.options.values();
    r.variant = tc.variant;
    r.display = tc.display ? display_json(*tc.display) : json();
    r.tags = tc.tags;
    r.bless_command = bless_command(tc, store);
    return r;
}

RenderFigures render_figures(const RenderResult& rr) {
    RenderFigures f;
    f.width = rr.image.cols;
    f.height = rr.image.rows;
    for (auto& p : rr.timings) {
        f.timings.push_back({p.name, p.ms, p.gpu, p.precompute});
        (p.precompute ? f.precompute_ms : f.frame_ms) += p.ms;
    }
    f.texture_fetches_per_pixel = rr.texture_fetches_per_pixel;
    if (rr.texture_bytes > 0) { // the bytes/accuracy chart's x (mobile: the prefiltered chain)
        f.texture_bytes = rr.texture_bytes;
        f.texel_count = rr.texel_count;
    }
    f.cost = render_cost(rr);
    f.provenance = rr.provenance;
    return f;
}

// Per-frame time of `repeats` renders in all (the first one already recorded in `figures`): wall
// times vary 2-5x on a loaded machine, so the results keep every sample and report their median.
void repeat_timings(RenderFigures& figures, const TestCase& tc, Worker& w, int repeats) {
    if (repeats < 2) return;
    std::vector<double> frame{figures.frame_ms};
    for (int k = 1; k < repeats; ++k) {
        double f = 0;
        for (auto& p : w.renderer.render(tc.spec).timings) f += p.precompute ? 0 : p.ms;
        frame.push_back(f);
    }
    set_frame_samples(figures, std::move(frame));
}

// One test under way: what its checks read, and what they found (the verdicts in order and the
// messages that say why; the test's verdict is the worst of them).
struct TestRun {
    const TestCase& tc;
    Worker& w;
    const GoldenStore& store;
    Artefacts art;
    int flip_threads;
    TestResult r;
    std::vector<Verdict> verdicts;
    std::vector<std::string> problems;

    void add(Verdict v, const std::string& message) {
        verdicts.push_back(v);
        if (!message.empty()) problems.push_back(message);
    }
};

// The render as the report shows it: test.png (+ its EXR) and which sphere is where.
void record_images(TestRun& t, const RenderResult& rr) {
    t.r.image = t.art.png("test.png", rr.image);
    t.r.image_exr = Artefacts::exr(*t.r.image);
    t.r.layout = t.art.layout(rr.coverage);
}

// A file environment must be the one the golden was made from (its content hash in the sidecar): an
// edited HDRI used to be judged against the old truth and baselines without a word.
void check_environment_unchanged(const TestCase& tc, const RenderResult& rr, const std::string& recorded, const fs::path& golden,
                                 const std::string& fix) {
    const std::string now = rr.provenance.contains("env_hash") ? rr.provenance["env_hash"].get<std::string>() : "";
    if (!is_environment_file(tc.spec.env) || recorded.empty() || now.empty() || recorded == now) return;
    throw InputError(fmt::format("{}: its content changed since {} was made from it (content hash {} there, {} now); {}",
                                 tc.spec.env, golden.string(), recorded, now, fix));
}

// The approved baselines and, when there is one, the cost approved with it and the platform it was
// blessed on (a difference is named in the message of a test that does not pass).
BaselineOutcome check_baselines(TestRun& t, const RenderResult& rr) {
    BaselineOutcome base = judge_against_baselines(t.tc, rr, t.store, t.art, t.flip_threads);
    t.r.comparisons.push_back(base.comparison);
    if (base.missing) {
        t.add(base.comparison.verdict, base.comparison.message);
        return base;
    }
    // The truth was made from the old file too: it is re-rendered first (bless measures the accuracy against it).
    const std::string rebless = "re-bless after looking at it: " + bless_command(t.tc, t.store);
    check_environment_unchanged(
        t.tc, rr,
        (base.golden.provenance.value("env_hash", json()).is_string() ? base.golden.provenance["env_hash"].get<std::string>()
                                                                      : ""),
        base.golden.image_path,
        t.tc.reference ? "re-render its truth: " + truth_command(t.tc.spec, t.store) + " --force; " + rebless : rebless);
    t.r.comparisons.back().approved = baseline_facts(base.golden.provenance);
    t.add(base.comparison.verdict, base.comparison.message.empty() ? "" : "baseline: " + base.comparison.message);
    const Comparison cost = cost_comparison(t.tc, rr, base);
    t.r.comparisons.push_back(cost);
    t.add(cost.verdict, cost.message);
    std::string diff = platform_difference(base.golden.provenance, rr.provenance, this_cpu_class());
    if (!diff.empty()) t.r.driver_mismatch = diff;
    return base;
}

// The accuracy the baseline approved (null without one): the bands of the truth and stability checks.
json approved_accuracy(const BaselineOutcome& base) { return base.golden.provenance.value("accuracy", json()); }

// A sidecar must carry what the test judges: a number for every metric of the reference band.
// Missing, a string or a misspelt key used to drop the truth check silently (the test passed).
void check_approved_accuracy(const TestRun& t, const BaselineOutcome& base) {
    if (!t.tc.baseline || base.missing || t.tc.reference_band.empty()) return;
    const json accuracy = approved_accuracy(base);
    const std::string side = fs::path(base.golden.image_path).replace_extension(".json").string();
    const std::string fix = "; re-create it with: " + bless_command(t.tc, t.store);
    if (!accuracy.is_object())
        throw InputError(side + ": \"accuracy\" is " + (accuracy.is_null() ? "missing" : "not an object") +
                         " (the test's reference_band judges it)" + fix);
    for (const auto& [metric, band] : t.tc.reference_band)
        if (!accuracy.contains(metric) || !accuracy[metric].is_number())
            throw InputError(fmt::format("{}: \"accuracy\" has no number for \"{}\" (the test's reference_band judges it){}",
                                         side, metric, fix));
}

// Against the truth: a test that asks for it ("reference": true) must have its reference golden
// (a deleted one used to drop the check silently). Returns the golden's image.
cv::Mat check_reference(TestRun& t, const RenderResult& rr, const BaselineOutcome& base) {
    auto ref = t.store.reference(t.tc.spec);
    if (!ref)
        throw InputError(t.store.reference_path(t.tc.spec).string() +
                         ": no reference golden, and the test asks for one (\"reference\": true); create it with: " +
                         truth_command(t.tc.spec, t.store) + " (or set \"reference\": false in the suite)");
    check_environment_unchanged(t.tc, rr, truth_env_hash(ref->provenance), ref->image_path,
                                "re-render the truth with: " + truth_command(t.tc.spec, t.store));
    check_approved_accuracy(t, base);
    TruthComparison truth = judge_against_truth(t.tc, rr, *ref, t.store, approved_accuracy(base), t.art, t.flip_threads);
    t.r.accuracy = truth.accuracy;
    t.r.per_sphere = truth.per_sphere;
    const Comparison& c = t.r.comparisons.emplace_back(std::move(truth.comparison));
    t.add(c.verdict, c.message.empty() ? "" : "accuracy: " + c.message);
    return ref->image;
}

void check_temporal(TestRun& t) {
    TemporalOutcome o = run_temporal(t.tc, t.w, t.store, t.art.dir, t.art.rel, t.flip_threads);
    t.r.temporal = o.json;
    for (const Check& k : o.checks) t.add(k.status, k.message.empty() ? "" : "temporal: " + k.message);
}

void check_stability(TestRun& t, const cv::Mat& image, const cv::Mat& reference, const BaselineOutcome& base) {
    StabilityOutcome s = run_stability(t.tc, t.w, image, reference, approved_accuracy(base), t.flip_threads);
    t.r.stability = s.json;
    t.add(stability_verdict(s.deterministic, s.flaky, t.tc.stability.fail_on_flaky), s.problem);
}

// The test's verdict (the worst found) and its message (every problem; the platform difference
// too when the test did not pass).
Verdict decide(TestRun& t) {
    t.r.verdict = overall_verdict(t.verdicts);
    t.r.message = test_message(t.problems, t.r.verdict, t.r.driver_mismatch);
    return t.r.verdict;
}

TestResult run_test_stages(const TestCase& tc, Worker& w, const GoldenStore& store, const std::filesystem::path& out_dir,
                           int flip_threads, int timing_repeats, bool& shader_error) {
    TestRun t{tc, w, store, Artefacts::for_test(out_dir, tc.name), flip_threads, test_header(tc, store), {}, {}};
    cv::Mat image;
    try {
        RenderResult rr = w.renderer.render(tc.spec);
        image = rr.image;
        t.r.render = render_figures(rr);
        repeat_timings(*t.r.render, tc, w, timing_repeats);
        if (NonFinite nf = find_non_finite(rr.image); nf.count) throw NonFiniteRender("render: " + nf.describe());
        if (!rr.non_finite_coverage.empty()) throw NonFiniteRender(rr.non_finite_coverage);
        if (t.art) record_images(t, rr);
        const BaselineOutcome base = tc.baseline ? check_baselines(t, rr) : BaselineOutcome{};
        const cv::Mat reference = tc.reference ? check_reference(t, rr, base) : cv::Mat();
        if (tc.reference) t.r.furnace = furnace_figure(tc, w, store); // energy against the white-furnace truth
        if (tc.temporal.frames > 0) check_temporal(t);
        if (tc.stability.enabled) check_stability(t, rr.image, reference, base);
    } catch (const ShaderCompileError& e) {
        shader_error = true;
        t.add(stop_verdict(TestStop::shader_compile_error), std::string("shader compile failed: ") + e.what());
    } catch (const NonFiniteRender& e) {
        t.add(stop_verdict(TestStop::non_finite_render), e.what());
    } catch (const std::exception& e) {
        t.add(stop_verdict(TestStop::cannot_test), e.what());
    }
    // A test that did not pass keeps its render at full precision beside the results. This runs on a
    // worker thread: an exception here (a full disk) used to escape it and abort the run (SIGABRT).
    if (decide(t) != Verdict::pass && t.art && !image.empty()) try {
            t.art.keep_float_render(image);
        } catch (const std::exception& e) {
            t.add(stop_verdict(TestStop::cannot_test), e.what());
            decide(t);
        }
    return std::move(t.r);
}

} // namespace

TestResult run_test(const TestCase& tc, Worker& w, const GoldenStore& store, const std::filesystem::path& out_dir,
                    int flip_threads, int timing_repeats, bool& shader_error) {
    const auto t0 = std::chrono::steady_clock::now();
    TestResult r;
    {
        ProfileStage stage("test_other"); // what no stage inside names: verdicts, sidecars, the results object
        r = run_test_stages(tc, w, store, out_dir, flip_threads, timing_repeats, shader_error);
    }
    // The whole test, its header included, so that its stages (all inside) add up to at most this.
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (profile::enabled()) r.profile = profile::take(); // --profile: seconds per stage (run_profile.h)
    return r;
}

} // namespace iblcheck
