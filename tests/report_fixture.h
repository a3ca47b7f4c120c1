// Synthetic runs for the report's tests (test_report.cpp, test_report_data.cpp,
// test_report_browser.cpp): results JSON plus the files a run writes (PNGs, half-float EXRs, sphere
// id maps), made without rendering. small_run() is built in report_fixture.cpp, make_ci_run() in
// report_ci_fixture.cpp, both from the images of report_fixture_images.h.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace iblcheck::testutil {

extern const std::string kEvilName;

// Nine tests, one of each verdict and then some (temporal frames, a missing image, an evil name),
// small images (192x48), a history of six older runs, and the report written once.
struct SmallRun {
    std::filesystem::path root, results_dir, out_dir;
    nlohmann::json results;
    std::vector<nlohmann::json> history;
};
SmallRun& small_run();

// A ci-like run: `passing` passing tests on 528x96 sweeps of 22 spheres (metal r=0..1 above,
// dielectric below), and first `failing` failing tests (variants mip_mapping=ue4,storage=vK, as
// one shader constant fails them) whose baselines differ on one sphere ("metal r=0.5", index 5) by
// 30 %; failing_* describe the first. Results and files under `dir`.
struct CiRun {
    std::filesystem::path dir;
    nlohmann::json results;
    std::string failing_name;
    cv::Mat failing_test, failing_error; // linear RGB CV_32FC3 and FLIP-like map CV_32FC1
    int pixels_over_002 = 0;             // of failing_error (the mask's default threshold 0.02)
    int width = 528, height = 96;
};
CiRun make_ci_run(const std::filesystem::path& dir, int passing, int failing);

} // namespace iblcheck::testutil
