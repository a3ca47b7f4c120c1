#include "worker.h"

#include <fmt/core.h>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "metrics/display_transform.h"
#include "sequence_store.h"

namespace iblcheck {

namespace {
vk::ContextOptions context_options(const std::string& device) {
    vk::ContextOptions o;
    o.device = device;
    return o;
}
} // namespace

Worker::Worker(const std::string& device) : renderer(context_options(device)), device(device) {}

const std::vector<cv::Mat>& Worker::sequence(TestSpec spec, int frames) {
    const std::string key = sequence_spec_text(spec, frames);
    auto it = sequences.find(key);
    if (it != sequences.end()) return it->second;
    const auto render_frame = [&](int f) {
        spec.options.set("frame", std::to_string(f));
        return renderer.render(spec);
    };
    // Frame 0 always renders; the frames after it come from the store when its entry's frame 0 is
    // this one byte for byte (sequence_store.h).
    RenderResult first = render_frame(0);
    std::vector<cv::Mat> raw{first.image};
    const std::string stored = sequence_store_key(spec, frames, first.provenance);
    std::optional<std::vector<cv::Mat>> all;
    {
        ProfileStage stage("sequence_store");
        if (stored_sequences) all = load_sequence(stored, first.image, frames);
    }
    if (all) {
        raw = std::move(*all);
    } else {
        for (int f = 1; f < frames; ++f) raw.push_back(render_frame(f).image);
        ProfileStage stage("sequence_store");
        save_sequence(stored, raw);
    }
    std::vector<cv::Mat> out;
    for (int f = 0; f < frames; ++f) {
        if (NonFinite nf = find_non_finite(raw[size_t(f)]); nf.count)
            throw NonFiniteRender(fmt::format("{} {} frame {}: {}", spec.method, spec.scene, f, nf.describe()));
        out.push_back(display_transform(raw[size_t(f)]));
    }
    return sequences.emplace(key, std::move(out)).first->second;
}

} // namespace iblcheck
