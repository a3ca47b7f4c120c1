#include "temporal_check.h"

#include <fmt/core.h>

#include "metrics/flip.h"
#include "metrics/image_io.h"
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
} // namespace

TemporalOutcome run_temporal(const TestCase& tc, Worker& w, const fs::path& img_dir, const std::string& rel_dir,
                             int flip_threads) {
    const TemporalSpec& ts = tc.temporal;
    TestSpec off = tc.spec, ref = tc.spec;
    off.options.set("specular_aa", "off");
    ref.options.set("specular_aa", "off");
    ref.options.set("ssaa", std::to_string(ts.reference_ssaa * tc.spec.options.get_int("ssaa", 2)));
    const auto& test_frames = w.sequence(tc.spec, ts.frames);
    const auto& off_frames = w.sequence(off, ts.frames);
    const auto& ref_frames = w.sequence(ref, ts.frames);
    SequenceScore st = score_sequence(test_frames, ref_frames, flip_threads);
    SequenceScore so = score_sequence(off_frames, ref_frames, flip_threads);
    TemporalOutcome out;
    json& j = out.json;
    j = {{"frames_count", ts.frames},
         {"flicker", st.flicker},
         {"variation_ratio", st.variation_ratio},
         {"flip_mean", st.flip_mean},
         {"off", {{"flicker", so.flicker}, {"variation_ratio", so.variation_ratio}, {"flip_mean", so.flip_mean}}},
         {"flicker_ratio", so.flicker > 0 ? st.flicker / so.flicker : 1.0},
         {"flip_ratio", so.flip_mean > 0 ? st.flip_mean / so.flip_mean : 1.0}};
    j["checks"] = json::array();
    for (auto& [metric, bound] : ts.checks) {
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
