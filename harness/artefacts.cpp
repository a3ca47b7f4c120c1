#include "artefacts.h"

#include <map>
#include <mutex>
#include <optional>

#include "golden_store.h"
#include "image_io/image_hash.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/profile.h"
#include "metrics/display_transform.h"
#include "sphere_errors.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {
std::mutex& drawn_mutex() {
    static std::mutex m;
    return m;
}
std::map<std::string, fs::path>& drawn() {
    static std::map<std::string, fs::path> files;
    return files;
}
} // namespace

Artefacts Artefacts::for_test(const fs::path& out_dir, const std::string& test) {
    if (out_dir.empty()) return {};
    return {out_dir / "images" / safe_file_name(test), "images/" + safe_file_name(test) + "/"};
}

std::string Artefacts::exr(const std::string& png) { return png.substr(0, png.rfind('.')) + ".exr"; }

namespace {
// The PNGs of a run's pictures already written, by their pixels' hash: a baseline equal to the render
// is the render's picture, and a truth is the reference of many tests (issue 33: the ci suite drew the
// sweep's two truths 43 times). Another is copied from the first file instead of drawn again.
std::optional<fs::path> drawn_png(const std::string& hash) {
    std::lock_guard lock(drawn_mutex());
    auto it = drawn().find(hash);
    if (it == drawn().end()) return std::nullopt;
    std::error_code ec;
    if (!fs::is_regular_file(it->second, ec)) return std::nullopt; // an earlier run's folder, gone
    return it->second;
}
} // namespace

std::string Artefacts::png(const std::string& name, const cv::Mat& linear, bool with_exr) const {
    ProfileStage stage("files");
    fs::create_directories(dir);
    const fs::path file = dir / name;
    const std::string hash = image_hash(linear);
    std::error_code ec;
    const std::optional<fs::path> earlier = drawn_png(hash);
    if (!earlier || !fs::copy_file(*earlier, file, fs::copy_options::overwrite_existing, ec) || ec) {
        write_png(file.string(), display_transform(linear));
        std::lock_guard lock(drawn_mutex());
        if (drawn().size() >= 64) drawn().clear();
        drawn()[hash] = file;
    }
    if (with_exr) write_exr_half((dir / exr(name)).string(), linear);
    return rel + name;
}

std::string Artefacts::shared_exr(const std::string& golden_rel, const cv::Mat& linear) const {
    ProfileStage stage("files");
    const fs::path shared = dir.parent_path() / "_goldens";
    const std::string file = safe_file_name(golden_rel);
    if (!fs::exists(shared / file)) { // two workers (or processes) may both write it: same pixels, atomic rename
        fs::create_directories(shared);
        write_file_atomically(shared / file, [&](const fs::path& tmp) { write_exr_half(tmp.string(), linear); });
    }
    return "images/_goldens/" + file;
}

std::string Artefacts::heatmap(const std::string& name, const cv::Mat& errmap) const {
    ProfileStage stage("files");
    fs::create_directories(dir);
    write_png((dir / name).string(), magma_heatmap(errmap));
    write_exr_half((dir / exr(name)).string(), errmap);
    return rel + name;
}

json Artefacts::images(const std::string& test, const std::string& golden, const std::string& heatmap) {
    return {{"test", test},          {"golden", golden},          {"heatmap", heatmap},
            {"test_exr", exr(test)}, {"golden_exr", exr(golden)}, {"error_exr", exr(heatmap)}};
}

json Artefacts::layout(const SphereCoverage& coverage) const {
    ProfileStage stage("files");
    SphereLayout l = sphere_layout(coverage);
    if (l.ids.empty()) return nullptr;
    fs::create_directories(dir);
    cv::Mat ids;
    l.ids.convertTo(ids, CV_32F, 1.0 / 255.0);
    write_png((dir / "spheres.png").string(), ids);
    return {{"id_map", rel + "spheres.png"}, {"spheres", l.spheres}};
}

void Artefacts::keep_float_render(const cv::Mat& image) const {
    ProfileStage stage("files");
    fs::create_directories(dir);
    write_exr((dir / "test.exr").string(), image);
}

} // namespace iblcheck
