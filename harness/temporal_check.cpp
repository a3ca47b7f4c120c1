#include "temporal_check.h"

#include <fmt/core.h>

#include <cmath>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/display_transform.h"
#include "metrics/flip.h"
#include "metrics/temporal.h"

using nlohmann::json;
namespace fs = std::filesystem;

namespace iblcheck {

namespace {
struct SequenceScore {
    double flicker = 0, variation_ratio = 0, flip_mean = 0;
};

SequenceScore score_sequence(const std::vector<cv::Mat>& test, const std::vector<cv::Mat>& ref, int flip_threads) {
    SequenceScore s;
    TemporalResult t = compute_temporal(test, ref);
    s.flicker = t.flicker;
    s.variation_ratio = t.variation_ratio;
    FlipOptions fo;
    fo.threads = flip_threads;
    for (size_t i = 0; i < test.size(); ++i) s.flip_mean += compute_flip_ldr(ref[i], test[i], fo).mean;
    s.flip_mean /= double(test.size());
    return s;
}
// score_sequence of two sequences the worker holds, computed once per worker (Worker::sequence_scores).
SequenceScore held_score(Worker& w, const std::vector<cv::Mat>& test, const std::vector<cv::Mat>& ref, int flip_threads) {
    const auto [it, fresh] = w.sequence_scores.try_emplace({&test, &ref});
    if (fresh) {
        const SequenceScore s = score_sequence(test, ref, flip_threads);
        it->second = {s.flicker, s.variation_ratio, s.flip_mean};
    }
    return {it->second[0], it->second[1], it->second[2]};
}
} // namespace

TemporalOutcome run_temporal(const TestCase& tc, Worker& w, const GoldenStore& store, const fs::path& img_dir,
                             const std::string& rel_dir, int flip_threads) {
    const TemporalSpec& ts = tc.temporal;
    TestSpec off = without_specular_aa(tc.spec), ref = temporal_reference_spec(tc);
    const auto& test_frames = w.sequence(tc.spec, ts.frames);
    const auto& off_frames = w.sequence(off, ts.frames);
    const auto& ref_frames = w.sequence(ref, ts.frames);
    // The `off` test's own sequence is the off one (the same object): its two scores are one.
    SequenceScore st = held_score(w, test_frames, ref_frames, flip_threads);
    SequenceScore so = held_score(w, off_frames, ref_frames, flip_threads);
    TemporalOutcome out;
    json& j = out.json;
    j = {{"frames_count", ts.frames},
         {"flicker", st.flicker},
         {"variation_ratio", st.variation_ratio},
         {"flip_mean", st.flip_mean},
         {"off", {{"flicker", so.flicker}, {"variation_ratio", so.variation_ratio}, {"flip_mean", so.flip_mean}}},
         {"flicker_ratio", so.flicker > 0 ? st.flicker / so.flicker : 1.0},
         {"flip_ratio", so.flip_mean > 0 ? st.flip_mean / so.flip_mean : 1.0},
         {"reference", {{"method", ref.method}, {"options", ref.options.canonical()}}}};
    // The truth: the same scene's quadrature truth, frame by frame (no method-specific options).
    TestSpec truth_spec;
    truth_spec.scene = tc.spec.scene, truth_spec.env = tc.spec.env, truth_spec.env_name = tc.spec.env_name,
    truth_spec.width = tc.spec.width, truth_spec.height = tc.spec.height;
    for (const char* k : {"roughness", "metallic", "base_color", "env_rotation"})
        if (tc.spec.options.has(k)) truth_spec.options.set(k, *tc.spec.options.get_string(k));
    std::vector<cv::Mat> truth_linear;
    const std::optional<Golden> truth = store.reference_sequence(truth_spec, ts.frames, truth_linear);
    if (truth) {
        std::vector<cv::Mat> truth_frames;
        for (const cv::Mat& m : truth_linear) truth_frames.push_back(display_transform(m));
        const SequenceScore tt = score_sequence(test_frames, truth_frames, flip_threads);
        const SequenceScore to = &off_frames == &test_frames ? tt : score_sequence(off_frames, truth_frames, flip_threads);
        const SequenceScore tr = score_sequence(ref_frames, truth_frames, flip_threads);
        j["truth"] = {
            {"golden", store.relative(truth->image_path)},
            {"error_bound", truth->provenance.value("error_bound", json())},
            {"flicker", tt.flicker},
            {"variation_ratio", tt.variation_ratio},
            {"flip_mean", tt.flip_mean},
            {"off", {{"flicker", to.flicker}, {"variation_ratio", to.variation_ratio}, {"flip_mean", to.flip_mean}}},
            {"reference", {{"flicker", tr.flicker}, {"variation_ratio", tr.variation_ratio}, {"flip_mean", tr.flip_mean}}},
            {"flip_ratio", to.flip_mean > 0 ? tt.flip_mean / to.flip_mean : 1.0}};
        j["truth_flicker"] = tt.flicker;
        j["truth_flip_mean"] = tt.flip_mean;
        j["truth_flip_ratio"] = j["truth"]["flip_ratio"];
    } else {
        j["truth"] = {{"missing", store.relative(store.reference_sequence_path(truth_spec, ts.frames))}};
    }
    j["checks"] = json::array();
    for (auto& [metric, bound] : ts.checks) {
        // A truth check without the truth golden cannot judge: an input error (exit 2, bisect 125),
        // like a missing reference golden, not a regression.
        if (!j.contains(metric))
            throw InputError(store.reference_sequence_path(truth_spec, ts.frames).string() +
                             ": no temporal truth golden, and the test's check " + metric +
                             " judges against it (TEMPORAL=only scripts/regenerate_reference_goldens.sh writes it)");
        Check c = judge_bound("temporal." + metric, j[metric].get<double>(), bound);
        j["checks"].push_back(to_json(c));
        out.checks.push_back(std::move(c));
    }
    if (!img_dir.empty()) {
        fs::create_directories(img_dir);
        for (int f = 0; f < ts.frames; ++f) {
            std::string tf = fmt::format("frame{:03d}.png", f), rf = fmt::format("ref{:03d}.png", f);
            write_png((img_dir / tf).string(), test_frames[size_t(f)]);
            write_png((img_dir / rf).string(), ref_frames[size_t(f)]);
            j["frames"].push_back(rel_dir + tf);
            j["reference_frames"].push_back(rel_dir + rf);
        }
    }
    return out;
}

} // namespace iblcheck
