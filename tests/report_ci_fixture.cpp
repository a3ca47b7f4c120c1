// make_ci_run() (report_fixture.h): a ci-like run of roughness sweeps, built one test at a time.
#include <fstream>

#include <fmt/format.h>

#include "image_io/image_io.h"
#include "metrics/display_transform.h"
#include "tests/report_fixture.h"
#include "tests/report_fixture_images.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck::testutil {

using namespace fixture;

namespace {

// One ci-like test's baseline comparison: its images, the approved sidecar, FLIP mean and checks.
json ci_baseline_comparison(const std::string& name, bool fail, double mean) {
    json imgs = images(name, "baseline");
    if (!fail) imgs["golden_exr"] = imgs["test_exr"]; // bit-identical: the harness shares the file
    json cmp = {
        {"kind", "baseline"},
        {"golden", "baseline/" + name + ".exr"},
        {"verdict", fail ? "fail" : "pass"},
        {"images", imgs},
        {"approved",
         {{"commit", "da34be9deabf"},
          {"date", "2026-11-23T03:15:06Z"},
          {"shader_tree_hash", fail ? "d7aa188baa82dc22" : "3f2167d7d4701f9b"},
          {"driver_info", "Mesa 22.3.6 (LLVM 15.0.6)"},
          {"cpu_class", "avx2-fma-f16c-256"}}},
        {"metrics", {{"flip", {{"mean", mean}, {"block_x", 240}, {"block_y", 16}}}}},
        {"checks",
         json::array(
             {{{"metric", "flip.mean"},
               {"value", mean},
               {"min", nullptr},
               {"max", 0.001},
               {"status", fail ? "fail" : "pass"},
               {"message", fmt::format("flip.mean {:.4g} > 0.001", mean)}},
              {{"metric", "flip.p99"}, {"value", 0.3}, {"min", nullptr}, {"max", 0.02}, {"status", fail ? "fail" : "pass"}}})}};
    if (fail) cmp["worst_block"] = {{"x", 240}, {"y", 16}, {"flip", 0.26}, {"sphere", "metal r=0.5"}};
    return cmp;
}

// The baseline of a failing ci test: `test` 30 % brighter on metal r=0.5 (index 5).
cv::Mat brighter_on_sphere_5(const cv::Mat& test, int H) {
    cv::Mat base = test.clone();
    const int cx = 24 + 48 * 5, cy = H / 4;
    for (int y = 0; y < H / 2; ++y)
        for (int x = cx - 22; x <= cx + 22; ++x)
            if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= 400) base.at<cv::Vec3f>(y, x) *= 1.3f;
    return base;
}

// The mean of an error map and its pixels over the mask's default threshold 0.02.
std::pair<double, int> error_stats(const cv::Mat& err) {
    double mean = 0;
    int over = 0;
    for (int y = 0; y < err.rows; ++y)
        for (int x = 0; x < err.cols; ++x) {
            mean += err.at<float>(y, x);
            over += err.at<float>(y, x) > 0.02f;
        }
    mean /= err.cols * err.rows;
    return {mean, over};
}

// Test k of a ci run (failing or passing): its images under run.dir and its results object.
json ci_test(CiRun& run, const json& spheres_json, int k, bool fail) {
    const fs::path& dir = run.dir;
    const int W = run.width, H = run.height;
    const std::string env = k % 2 ? "sky_sun" : "studio";
    // Failures share an option (as the tests one shader constant breaks do): mip_mapping=ue4.
    const std::string variant = k == 0 ? "default" : fmt::format("{}storage=v{}", fail ? "mip_mapping=ue4," : "", k);
    const std::string name = fmt::format("mobile.roughness_sweep.{}.{}", env, variant);
    const std::string d = "images/" + name + "/";
    cv::Mat test = spheres(W, H, 2, 1.0f + 0.01f * float(k), env == "sky_sun");
    cv::Mat base = fail ? brighter_on_sphere_5(test, H) : test.clone();
    const cv::Mat err = error_map(test, base);
    write_image(dir, d + "test.png", test);
    write_png((dir / (d + "baseline.png")).string(), display_transform(base));
    if (fail) write_exr_half((dir / (d + "baseline.exr")).string(), base);
    write_error(dir, d + "baseline_flip.png", err);
    write_png((dir / (d + "spheres.png")).string(), sphere_ids(W, H, 2));
    json t = {{"name", name},
              {"suite", "ci"},
              {"scene", "roughness_sweep"},
              {"method", "mobile"},
              {"env", env},
              {"variant", variant},
              {"options", json::object()},
              {"width", W},
              {"height", H},
              {"verdict", fail ? "fail" : "pass"},
              {"image", d + "test.png"},
              {"image_exr", d + "test.exr"},
              {"layout", {{"id_map", d + "spheres.png"}, {"spheres", spheres_json}}},
              {"bless_command", "iblcheck bless --suite 'ci' --filter '" + name + "'"},
              {"accuracy", {{"flip_mean", 0.2 + 0.001 * k}}},
              {"cost", {{"spirv_instructions_per_pixel", 6276.0 + k}, {"texture_fetches_per_pixel", 2.54}}},
              {"frame_ms", 150.0 + k},
              {"precompute_ms", 200.0}};
    const auto [mean, over] = error_stats(err);
    t["comparisons"] = json::array({ci_baseline_comparison(name, fail, mean)});
    t["provenance"] = {{"shader_tree_hash", "3f2167d7d4701f9b"}};
    t["message"] = fail ? "baseline: flip.mean > 0.001" : "";
    if (fail && run.failing_name.empty()) {
        run.failing_name = name;
        run.failing_test = test;
        run.failing_error = err;
        run.pixels_over_002 = over;
    }
    return t;
}

json ci_run_results(const json& tests) {
    return {{"schema", "iblcheck-results/1"},
            {"suite", "ci"},
            {"command", "iblcheck run --suite ci --out report"},
            {"started", "2026-11-23T06:12:15Z"},
            {"total_s", 27.6},
            {"commit", "039aeff2a6fb"},
            {"dirty", false},
            {"cpu_class", "avx2-fma-f16c-256"},
            {"driver",
             {{"device", "llvmpipe (LLVM 15.0.6, 256 bits)"},
              {"driver_info", "Mesa 22.3.6 (LLVM 15.0.6)"},
              {"mesa", "22.3.6"},
              {"llvm", "15.0.6"},
              {"api", "1.3.230"}}},
            {"tests", tests}};
}
} // namespace

CiRun make_ci_run(const fs::path& dir, int passing, int failing) {
    CiRun run;
    run.dir = dir;
    fs::create_directories(dir);
    json tests = json::array();
    const json spheres_json = sphere_list(run.width / 48, 2);
    for (int j = 0; j < failing; ++j) tests.push_back(ci_test(run, spheres_json, passing + j, true));
    for (int k = 0; k < passing; ++k) tests.push_back(ci_test(run, spheres_json, k, false));
    run.results = ci_run_results(tests);
    std::ofstream(dir / "results.json") << run.results.dump(1);
    return run;
}

} // namespace iblcheck::testutil