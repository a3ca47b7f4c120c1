#include "worker.h"

#include <fmt/core.h>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/display_transform.h"

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
    std::string key = spec.method + "|" + spec.scene + "|" + spec.env + "|" + std::to_string(spec.width) + "x" +
                      std::to_string(spec.height) + "|" + spec.options.canonical() + "|" + std::to_string(frames) + "|" +
                      spec.shader;
    auto it = sequences.find(key);
    if (it != sequences.end()) return it->second;
    std::vector<cv::Mat> out;
    for (int f = 0; f < frames; ++f) {
        spec.options.set("frame", std::to_string(f));
        cv::Mat img = renderer.render(spec).image;
        if (NonFinite nf = find_non_finite(img); nf.count)
            throw NonFiniteRender(fmt::format("{} {} frame {}: {}", spec.method, spec.scene, f, nf.describe()));
        out.push_back(display_transform(img));
    }
    return sequences.emplace(key, std::move(out)).first->second;
}

} // namespace iblcheck
