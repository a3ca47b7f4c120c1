#include "furnace_figure.h"

#include <cmath>

#include "kernel/profile.h"
#include "renderers/renderer.h"

using nlohmann::json;

namespace iblcheck {

namespace {

// Options that describe the scene or the cube's resolution, not the variant's shading: the furnace
// render drops them (its own scene; a 16² cube, which a constant environment fills exactly).
bool furnace_drops(const std::string& key) {
    for (const char* k : {"roughness", "metallic", "base_color", "frame", "bump_amplitude", "bump_frequency", "roughness_bias",
                          "camera_shift", "cube_size", "mips", "env_rotation", "ssaa"})
        if (key == k) return true;
    return false;
}

TestSpec furnace_spec(const TestCase& tc) {
    TestSpec s;
    s.scene = "furnace";
    s.env = "constant:1";
    s.method = tc.spec.method;
    s.shader = tc.spec.shader; // a team's shading: its own energy figure
    for (const auto& [k, v] : tc.spec.options.values())
        if (!furnace_drops(k)) s.options.set(k, v);
    s.options.set("cube_size", "16");
    s.options.set("ssaa", "1");
    return s;
}

// Whether the 3×3 neighbourhood of (x, y) shows the same sphere: the silhouette's pixels mix the
// sphere with the background differently in the render (one ray) and the truth (exact coverage).
bool interior(const cv::Mat& ids, int x, int y) {
    const int id = ids.at<int>(y, x);
    if (id < 0 || x < 1 || y < 1 || x + 1 >= ids.cols || y + 1 >= ids.rows) return false;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (ids.at<int>(y + dy, x + dx) != id) return false;
    return true;
}

// Mean of the green channel over each sphere's interior pixels (coverage ids), index = sphere.
std::vector<double> sphere_means(const cv::Mat& image, const SphereCoverage& coverage) {
    std::vector<double> sum(coverage.spheres.size(), 0.0), count(coverage.spheres.size(), 0.0);
    for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; ++x) {
            if (!interior(coverage.ids, x, y)) continue;
            const int id = coverage.ids.at<int>(y, x);
            sum[size_t(id)] += image.at<cv::Vec3f>(y, x)[1];
            count[size_t(id)] += 1;
        }
    for (size_t i = 0; i < sum.size(); ++i) sum[i] = count[i] > 0 ? sum[i] / count[i] : 0.0;
    return sum;
}

} // namespace

json furnace_figure(const TestCase& tc, Worker& w, const GoldenStore& store) {
    ProfileStage stage("furnace"); // its render's own stages are counted as theirs
    if (tc.spec.method != "mobile" && tc.spec.method != "sampled") return nullptr;
    const TestSpec spec = furnace_spec(tc);
    const std::optional<Golden> truth = store.reference(spec);
    if (!truth) return nullptr;
    const RenderResult rr = w.renderer.render(spec);
    if (rr.image.size() != truth->image.size()) return nullptr;
    const std::vector<double> got = sphere_means(rr.image, rr.coverage), want = sphere_means(truth->image, rr.coverage);
    json roughness = json::array(), error = json::array();
    double worst = 0;
    for (size_t i = 0; i < got.size(); ++i) {
        const double r = rr.coverage.spheres[i].roughness;
        if (r <= 0 || want[i] <= 0) continue; // the mirror reflects 1 in every variant
        const double e = got[i] / want[i] - 1;
        roughness.push_back(r);
        error.push_back(std::round(e * 1e5) / 1e5);
        if (std::fabs(e) > std::fabs(worst)) worst = e;
    }
    return {{"golden", std::filesystem::relative(truth->image_path, store.root()).generic_string()},
            {"roughness", roughness},
            {"relative_error", error},
            {"worst", std::round(worst * 1e5) / 1e5}};
}

} // namespace iblcheck
