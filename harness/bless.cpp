#include "bless.h"

#include <fmt/core.h>

#include <cstring>
#include <fstream>
#include <regex>

#include "golden_store.h"
#include "harness/common/errors.h"
#include "harness/common/input_file.h"
#include "image_compare.h"
#include "metrics/image_io.h"
#include "provenance.h"
#include "worker.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {
bool bit_identical(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

json read_sidecar(const fs::path& exr) {
    const fs::path side = fs::path(exr).replace_extension(".json");
    if (!fs::exists(side)) return json();
    std::ifstream f = open_input_file(side.string()); // a FIFO would block: refused
    return json::parse(f, nullptr, false);
}

// The accuracy against the reference golden that the reference band is built on.
json approved_accuracy(const GoldenStore& store, const TestSpec& spec, const cv::Mat& image) {
    auto ref = store.reference(spec);
    if (!ref || ref->image.size() != image.size()) return json::object();
    json m = compare_images(ref->image, image, 0);
    return {{"flip.mean", m["flip"]["mean"]},
            {"flip.p99", m["flip"]["p99"]},
            {"flip.block_max", m["flip"]["block_max"]},
            {"ssim.mean", m["ssim"]["mean"]},
            {"psnr.db", m["psnr"]["db"]}};
}

// What changed against the baseline already there: "new", "unchanged", or how it changed.
struct Change {
    bool pixels = true, judged = true; // pixels differ; a judged figure of the sidecar differs
    std::string text = "new";
};

Change change_against(const fs::path& path, const cv::Mat& image, const json& prov) {
    Change c;
    if (!fs::exists(path)) return c;
    cv::Mat old = read_image(path.string()).pixels;
    json oldp = read_sidecar(path);
    c.pixels = !bit_identical(old, image);
    c.judged = !oldp.is_object() || oldp.value("accuracy", json()) != prov["accuracy"] ||
               oldp.value("cost", json()) != prov["cost"] || oldp.value("size", json()) != prov["size"];
    if (!c.pixels)
        c.text = c.judged ? "pixels unchanged; sidecar's accuracy/cost updated" : "unchanged";
    else if (old.size() != image.size())
        c.text = fmt::format("changed size {}x{} -> {}x{}", old.cols, old.rows, image.cols, image.rows);
    else
        c.text = fmt::format("changed: FLIP vs old baseline {:.5f}", compare_images(old, image, 0)["flip"]["mean"].get<double>());
    if (oldp.is_object() && oldp.contains("accuracy") && oldp["accuracy"].contains("flip.mean") &&
        prov["accuracy"].contains("flip.mean") && oldp["accuracy"] != prov["accuracy"])
        c.text += fmt::format("; accuracy FLIP {:.5f} -> {:.5f}", oldp["accuracy"]["flip.mean"].get<double>(),
                              prov["accuracy"]["flip.mean"].get<double>());
    return c;
}
} // namespace

void check_label(const std::string& label) {
    static const std::regex ok("[A-Za-z0-9._-]+");
    if (!std::regex_match(label, ok))
        throw UsageError("--label '" + label + "': a label is one or more of A-Z a-z 0-9 . _ - (it names a file)");
}

std::string bless_command(const TestCase& t) {
    const std::string& suite = t.suite_arg.empty() ? t.suite : t.suite_arg;
    return "iblcheck bless --suite '" + suite + "' --filter '" + t.name + "'";
}

int bless(const BlessOptions& o) {
    if (o.label) check_label(*o.label);
    const std::string label = o.label.value_or("");
    Suite suite = load_suite(o.suite);
    std::vector<TestCase> tests = select_tests(suite, o.filter, 0, 1);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    Worker w(o.device);
    int failed = 0;
    const json common = run_provenance();
    for (const auto& tc : tests) {
        if (!tc.baseline) continue;
        RenderResult rr;
        try {
            rr = w.renderer.render(tc.spec);
            if (NonFinite nf = find_non_finite(rr.image); nf.count) throw NonFiniteRender(nf.describe());
        } catch (const std::exception& e) {
            fmt::print(stderr, "error: {}: render failed, not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        json prov = rr.provenance;
        prov["test"] = tc.name;
        prov["suite"] = tc.suite;
        prov["method"] = tc.spec.method;
        prov["variant"] = tc.variant;
        prov["size"] = {rr.image.cols, rr.image.rows};
        prov["label"] = label;
        prov["accuracy"] = approved_accuracy(store, tc.spec, rr.image);
        prov["cost"] = render_cost(rr);
        for (auto& [k, v] : common.items()) prov[k] = v;
        prov["command"] = bless_command(tc) + (o.label ? " --label " + label : "");
        const fs::path path = store.baseline_path(tc.name, label);
        Change change = change_against(path, rr.image, prov);
        if (!change.pixels && !change.judged) {
            fmt::print("{:<9} {}  (unchanged, left as it is)\n", "same", tc.name);
            continue;
        }
        if (o.dry_run) {
            fmt::print("{:<9} {}  ({})\n", "would", tc.name, change.text);
            continue;
        }
        try {
            if (change.pixels)
                GoldenStore::write_golden(path, rr.image, prov);
            else
                GoldenStore::write_sidecar(path, prov);
        } catch (const std::exception& e) {
            fmt::print(stderr, "error: {}: not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        fmt::print("{:<9} {}  ({})\n", "blessed", tc.name, change.text);
    }
    return failed ? kExitError : kExitPass;
}

} // namespace iblcheck
