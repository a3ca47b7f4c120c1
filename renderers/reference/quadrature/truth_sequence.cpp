// The temporal truth's frames (truth_sequence.h).
#include "renderers/reference/quadrature/truth_sequence.h"

#include <chrono>
#include <string>

#include "kernel/errors.h"
#include "kernel/parallel_for.h"
#include "renderers/option_table.h"

namespace iblcheck::truth {

TruthSequence render_truth_sequence(const TestSpec& spec, const Environment& env_in, int frames,
                                    const std::vector<int>& bound_frames, const Progress& progress) {
    const auto t0 = std::chrono::steady_clock::now();
    if (frames < 1) throw UsageError("temporal truth: frames must be >= 1, got " + std::to_string(frames));
    for (int f : bound_frames)
        if (f < 0 || f >= frames)
            throw UsageError("temporal truth: bound frame " + std::to_string(f) + " is outside 0.." + std::to_string(frames - 1));
    TruthSequence out;
    out.accuracy = TruthAccuracy::temporal();
    out.bound_frames = bound_frames;
    int threads = option_int(spec.options, "threads", "reference");
    if (threads < 0) throw UsageError("option 'threads': must be >= 0");
    out.threads = resolve_threads(threads);
    Environment env = env_in;
    if (spec.options.has("env_rotation")) env.rotation_deg = float(option_double(spec.options, "env_rotation", "reference"));
    const EnvPyramid pyramid(env);
    const std::string env_key = env.content_hash + "@" + std::to_string(env.rotation_deg);
    // Progress in units of a frame at the sequence's level; a finer frame counts 3 (measured: its table
    // and its deeper footprint refinement).
    const double total = double(frames) + 3.0 * double(bound_frames.size());
    double done = 0;
    auto part = [&](double weight) -> Progress {
        if (!progress) return {};
        const double lo = done / total, hi = (done + weight) / total;
        return [&progress, lo, hi](double f) { progress(lo + (hi - lo) * f); };
    };
    auto render_frame = [&](int f, const TruthAccuracy& acc, double weight) {
        OptionMap o = spec.options;
        o.set("frame", std::to_string(f));
        const Scene scene = build_scene(spec.scene, o);
        const int W = spec.width > 0 ? spec.width : scene.width, H = spec.height > 0 ? spec.height : scene.height;
        TruthImage img = render_truth_level(scene, W, H, pyramid, env_key, Lobes::all, acc, out.threads, part(weight));
        done += weight;
        return std::make_pair(scene, img);
    };
    std::vector<TruthImage> coarse(static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f) {
        auto [scene, img] = render_frame(f, out.accuracy, 1.0);
        out.frames.push_back(img.image);
        coarse[size_t(f)] = std::move(img);
    }
    for (int f : bound_frames) {
        auto [scene, img] = render_frame(f, out.accuracy.finer(), 3.0);
        out.bounds.push_back(compare_levels(coarse[size_t(f)], img, scene));
        out.finer.push_back(img.image);
    }
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

} // namespace iblcheck::truth
