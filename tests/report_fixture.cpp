// Synthetic runs for the report's tests (report_fixture.h).
#include "tests/report_fixture.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include <fmt/format.h>

#include "image_io/image_io.h"
#include "metrics/display_transform.h"
#include "reports/report_writer.h"
#include "tests/report_fixture_images.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck::testutil {

using namespace fixture;

const std::string kEvilName = "mobile.evil.<script>alert('x')</script>&\"q\"";

namespace {

json comparison(const std::string& kind, const std::string& dir, const std::string& verdict, double flip) {
    return json{{"kind", kind},
                {"golden", kind + "/x.exr"},
                {"verdict", verdict},
                {"metrics",
                 {{"flip",
                   {{"mean", flip},
                    {"weighted_median", flip * 0.8},
                    {"p99", flip * 10},
                    {"max", 0.5},
                    {"block_max", 0.2},
                    {"block_x", 96},
                    {"block_y", 16},
                    {"mode", "hdr"}}},
                  {"ssim", {{"mean", 0.99}}},
                  {"psnr", {{"db", 41.2}, {"rmse", 0.01}, {"max_abs", 0.3}}}}},
                {"worst_block", {{"x", 96}, {"y", 16}, {"flip", 0.2}, {"sphere", "metal r=0.3"}}},
                {"checks",
                 json::array({{{"metric", "flip.mean"},
                               {"value", flip},
                               {"min", nullptr},
                               {"max", 0.01},
                               {"status", flip > 0.01 ? "fail" : "pass"},
                               {"message", fmt::format("flip.mean {} > 0.01 (+{})", flip, flip - 0.01)}},
                              {{"metric", "ssim.mean"}, {"value", 0.99}, {"min", 0.98}, {"max", nullptr}, {"status", "pass"}}})},
                {"images", images(dir, kind)}};
}

json make_test(const std::string& method, const std::string& scene, const std::string& env, const std::string& variant,
               const std::string& verdict, const std::string& dir) {
    json t;
    t["name"] = method + "." + scene + "." + env + (variant.empty() ? "" : "." + variant);
    t["suite"] = "ci";
    t["scene"] = scene;
    t["method"] = method;
    t["env"] = env;
    t["variant"] = variant;
    t["options"] = json::object();
    if (!variant.empty()) {
        auto eq = variant.find('=');
        t["options"][variant.substr(0, eq)] = variant.substr(eq + 1);
    }
    t["width"] = 192;
    t["height"] = 48;
    t["verdict"] = verdict;
    t["message"] = verdict == "pass" ? "" : verdict + ": something";
    t["bless_command"] = "iblcheck bless --suite ci --filter '" + t["name"].get<std::string>() + "'";
    t["driver_mismatch"] = nullptr;
    t["image"] = "images/" + dir + "/test.png";
    t["image_exr"] = "images/" + dir + "/test.exr";
    t["layout"] = {{"id_map", "images/" + dir + "/spheres.png"}, {"spheres", sphere_list(4, 1)}};
    t["comparisons"] =
        json::array({comparison("baseline", dir, verdict == "fail" ? "fail" : "pass", verdict == "fail" ? 0.0123 : 0.004)});
    t["timings"] = json::array({{{"pass", "prefilter_ggx"}, {"ms", 12.1}, {"gpu", true}, {"precompute", true}},
                                {{"pass", "shade_spheres"}, {"ms", 3.2}, {"gpu", true}, {"precompute", false}}});
    return t;
}

json per_sphere(double scale) {
    json a = json::array();
    for (double r : {0.1, 0.4, 0.7, 1.0}) {
        a.push_back({{"label", "metal r=" + std::to_string(r).substr(0, 3)},
                     {"roughness", r},
                     {"metallic", 1},
                     {"flip_mean", scale * (0.02 + r * 0.05)}});
        a.push_back({{"label", "plastic r=" + std::to_string(r).substr(0, 3)},
                     {"roughness", r},
                     {"metallic", 0},
                     {"flip_mean", scale * (0.01 + r * 0.03)}});
    }
    return a; // 8 spheres
}

// The folder of this process's small run, removed when the test process ends (set
// IBLCHECK_KEEP_TMP=1 to look at the report).
SmallRun small_run_folders() {
    SmallRun f;
    f.root = fs::temp_directory_path() / ("iblcheck_test_report_" + std::to_string(::getpid()));
    fs::remove_all(f.root);
    static const fs::path cleanup = f.root;
    if (!std::getenv("IBLCHECK_KEEP_TMP"))
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(cleanup, ec);
        });
    f.results_dir = f.root / "run";
    f.out_dir = f.root / "report";
    return f;
}

// t1: a passing sampled test with per-sphere errors and repeated timings.
json sampled_pass_test() {
    json t1 = make_test("sampled", "roughness_sweep", "studio", "samples=64", "pass", "t1");
    t1["accuracy"] = {{"flip_mean", 0.011}, {"golden", "reference/roughness_sweep__studio.exr"}};
    t1["frame_ms"] = 31.0;
    t1["frame_ms_samples"] = {24.0, 31.0, 70.0};
    t1["precompute_ms"] = 4.0;
    t1["texture_fetches_per_pixel"] = 64;
    t1["cost"] = {{"spirv_instructions_per_pixel", 54000.0}, {"texture_fetches_per_pixel", 64}};
    t1["per_sphere"] = per_sphere(0.3);
    return t1;
}

// t2: the failing test: baseline and accuracy, a driver mismatch, stability, a shader tree changed
// since its baseline was blessed.
json failing_test() {
    json t2 = make_test("mobile", "roughness_sweep", "studio", "dominant_dir=lagarde", "fail", "t2");
    t2["message"] = "baseline: flip.mean 0.0123 > 0.0100 (+0.0023); worst 16x16 block at (96,16)";
    t2["driver_mismatch"] = "golden made with Mesa 22.3.5, this run Mesa 22.3.6";
    t2["accuracy"] = {{"flip_mean", 0.052}, {"golden", "reference/roughness_sweep__studio.exr"}};
    t2["frame_ms"] = 3.2;
    t2["precompute_ms"] = 40.1;
    t2["texture_fetches_per_pixel"] = 2.5;
    t2["cost"] = {{"spirv_instructions_per_pixel", 6300.0}, {"texture_fetches_per_pixel", 2.5}};
    t2["furnace"] = {{"golden", "reference/furnace__constant-1.exr"},
                     {"roughness", {0.25, 0.5, 0.75, 1.0}},
                     {"relative_error", {-0.13017, -0.18049, -0.08849, 0.16548}},
                     {"worst", -0.18049}};
    t2["texture_bytes"] = 1048512; // the prefiltered chain, RGBA16F
    t2["texel_count"] = 131064;
    t2["per_sphere"] = per_sphere(1.0);
    t2["stability"] = {{"noise_floor", {{"flip.mean", 0.0004}}}, {"margins", {{"flip.mean", 25.0}}}, {"flaky", false}};
    t2["comparisons"][0]["approved"] = {{"commit", "c3"},
                                        {"date", "2026-11-13T03:00:00Z"},
                                        {"shader_tree_hash", "aaaa"},
                                        {"driver_info", "Mesa 22.3.5"},
                                        {"cpu_class", "avx2"}};
    t2["provenance"] = {{"shader_tree_hash", "bbbb"}};
    json ref = comparison("reference", "t2", "pass", 0.052);
    ref["checks"] = json::array({{{"metric", "accuracy.flip.mean"},
                                  {"value", 0.052},
                                  {"approved", 0.030},
                                  {"min", 0.027},
                                  {"max", 0.033},
                                  {"status", "fail"},
                                  {"message", "accuracy.flip.mean 0.052 outside"}}});
    ref["verdict"] = "fail";
    t2["comparisons"].push_back(ref);
    return t2;
}

// t3 improved (ASTC-sized texture), t4 missing-golden, t5 error (no image).
void improved_missing_error_tests(json& tests) {
    json t3 = make_test("mobile", "roughness_sweep", "studio", "dominant_dir=none", "improved", "t3");
    t3["accuracy"] = {{"flip_mean", 0.061}};
    t3["frame_ms"] = 3.0;
    t3["precompute_ms"] = 38.0;
    t3["texture_fetches_per_pixel"] = 2.0;
    t3["cost"] = {{"spirv_instructions_per_pixel", 6200.0}};
    t3["texture_bytes"] = 62976; // ASTC 6x6
    tests.push_back(t3);

    json t4 = make_test("mobile", "furnace", "constant", "", "missing-golden", "t4");
    t4["comparisons"] = json::array(); // no golden: nothing to compare, the rendering alone
    tests.push_back(t4);

    json t5 = make_test("sampled", "broken", "sky_sun", "", "error", "t5");
    t5["message"] = "shader compile failed: prefilter.glsl:12: 'foo' : undeclared identifier";
    t5["comparisons"] = json::array();
    t5["accuracy"] = nullptr;
    t5.erase("image");
    t5.erase("image_exr");
    tests.push_back(t5);
}

// t6 (mobile, with reference frames) and t7 (sampled): 12-frame temporal tests.
void temporal_tests(json& tests) {
    json t6 = make_test("mobile", "rotation", "sky_sun", "temporal", "pass", "t6");
    t6["options"] = json::object();
    t6["accuracy"] = {{"flip_mean", 0.03}};
    t6["frame_ms"] = 3.5;
    t6["precompute_ms"] = 41.0;
    t6["texture_fetches_per_pixel"] = 2.5;
    t6["temporal"] = {{"frames", json::array()},
                      {"reference_frames", json::array()},
                      {"flicker", 0.01},
                      {"variation_ratio", 1.3},
                      {"flip_mean", 0.02}};
    for (int i = 0; i < 12; ++i) {
        t6["temporal"]["frames"].push_back(fmt::format("images/t6/frame{:03d}.png", i));
        t6["temporal"]["reference_frames"].push_back(fmt::format("images/t6/ref{:03d}.png", i));
    }
    tests.push_back(t6);

    json t7 = make_test("sampled", "rotation", "sky_sun", "temporal", "pass", "t7");
    t7["options"] = json::object();
    t7["accuracy"] = {{"flip_mean", 0.014}};
    t7["frame_ms"] = 28.0;
    t7["precompute_ms"] = 3.0;
    t7["texture_fetches_per_pixel"] = 64;
    t7["temporal"] = {{"frames", t6["temporal"]["frames"]}, {"flicker", 0.004}, {"flip_mean", 0.012}};
    tests.push_back(t7);
}

// The evil name (HTML in the name and the message), and t9, a reference test whose heatmap is missing.
void evil_and_reference_tests(json& tests) {
    json t8 = make_test("mobile", "evil", "studio", "", "pass", "evil");
    t8["name"] = kEvilName;
    t8["message"] = "<b>bold</b> & \"quoted\"";
    t8["accuracy"] = {{"flip_mean", 0.08}};
    t8["frame_ms"] = 2.0;
    t8["cost"] = {{"spirv_instructions_per_pixel", 4000.0}};
    tests.push_back(t8);

    json t9 = make_test("reference", "roughness_sweep", "studio", "", "pass", "t9");
    t9["comparisons"][0]["images"]["heatmap"] = "images/t9/does_not_exist.png"; // a placeholder, not an error
    t9["comparisons"][0]["images"].erase("error_exr");
    t9["frame_ms"] = 5000.0;
    tests.push_back(t9);
}

// The results document around `tests`, as the harness writes it.
json small_run_results(const json& tests) {
    return {{"schema", "iblcheck-results/1"},
            {"suite", "ci"},
            {"command", "iblcheck run --suite ci --out report"},
            {"started", "2026-11-22T15:40:00Z"},
            {"total_s", 41.2},
            {"commit", "f554dd9"},
            {"dirty", true},
            {"cpu_class", "avx2"},
            {"driver",
             {{"device", "llvmpipe (LLVM 15.0.6, 256 bits)"},
              {"driver", "llvmpipe"},
              {"driver_info", "Mesa 22.3.6 (LLVM 15.0.6)"},
              {"mesa", "22.3.6"},
              {"llvm", "15.0.6"},
              {"api", "1.3.230"}}},
            {"counts", {{"pass", 5}, {"fail", 1}, {"improved", 1}, {"missing-golden", 1}, {"error", 1}}},
            {"tests", tests}};
}

// Images: linear EXRs and their PNGs, error maps, sphere id maps, t6's frames.
void write_small_run_images(const fs::path& results_dir) {
    const int W = 192, H = 48;
    for (const char* d : {"t1", "t2", "t3", "t4", "t5", "t6", "t7", "evil", "t9"}) {
        const cv::Mat test = spheres(W, H, 1, 1.0f, false), base = spheres(W, H, 1, 1.1f, false);
        write_image(results_dir, std::string("images/") + d + "/test.png", test);
        write_image(results_dir, std::string("images/") + d + "/baseline.png", base);
        write_error(results_dir, std::string("images/") + d + "/baseline_flip.png", error_map(test, base));
        write_image(results_dir, std::string("images/") + d + "/reference.png", base);
        write_error(results_dir, std::string("images/") + d + "/reference_flip.png", error_map(test, base));
        write_png((results_dir / "images" / d / "spheres.png").string(), sphere_ids(W, H, 1));
    }
    for (int i = 0; i < 12; ++i) {
        cv::Mat fr = spheres(96, 48, 1, 1.0f + 0.1f * float(i % 3 == 1), false), rf = spheres(96, 48, 1, 1.0f, false);
        write_png((results_dir / fmt::format("images/t6/frame{:03d}.png", i)).string(), display_transform(fr));
        write_png((results_dir / fmt::format("images/t6/ref{:03d}.png", i)).string(), display_transform(rf));
    }
}

// History: 6 older runs; the failing test's accuracy jumped at c4.
void write_small_run_history(SmallRun& f, const std::string& failing_name) {
    for (int i = 0; i < 6; ++i) {
        json h = report::history_entry(f.results);
        h["commit"] = fmt::format("c{}", i);
        h["date"] = fmt::format("2026-11-{:02d}T03:00:00Z", 10 + i);
        h["dirty"] = false;
        for (auto& [name, v] : h["tests"].items()) {
            if (v.contains("flip_mean")) v["flip_mean"] = v["flip_mean"].get<double>() * (1 + 0.01 * (i % 2));
            if (v.contains("frame_ms")) v["frame_ms"] = v["frame_ms"].get<double>() * (1 + 0.02 * (i % 3));
        }
        h["tests"][failing_name]["flip_mean"] = i < 4 ? 0.030 : 0.052;
        h["tests"][failing_name]["verdict"] = i < 4 ? "pass" : "fail";
        report::append_history(f.root / "history.jsonl", h);
    }
    f.history = report::read_history(f.root / "history.jsonl");
}
} // namespace

SmallRun& small_run() {
    static SmallRun f = [] {
        SmallRun f = small_run_folders();
        // Listed passes first on purpose: the report must put failures first.
        json tests = json::array({sampled_pass_test(), failing_test()});
        improved_missing_error_tests(tests);
        temporal_tests(tests);
        evil_and_reference_tests(tests);
        f.results = small_run_results(tests);
        write_small_run_images(f.results_dir);
        std::ofstream(f.results_dir / "results.json") << f.results.dump(2);
        write_small_run_history(f, tests[1]["name"].get<std::string>());
        report::write_report(f.results, f.results_dir, f.out_dir, f.history);
        return f;
    }();
    return f;
}

} // namespace iblcheck::testutil
