// The truth's goldens (harness/truth/truth_golden.h): a user's golden and its sidecar, the temporal
// sequences' criterion, and every committed reference golden's stated bound. Beside the quadrature's own
// tests in the same program (test_reference_truth); here because the golden writer sits in the harness.
#include "harness/truth/truth_golden.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "image_io/image_io.h"

using namespace iblcheck;
using namespace iblcheck::truth;
namespace fs = std::filesystem;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_truth_golden {

namespace {
TestSpec spec_of(const std::string& scene, const std::string& env, int w = 0, int h = 0) {
    TestSpec s;
    s.scene = scene, s.env = env, s.method = "reference", s.width = w, s.height = h;
    return s;
}
} // namespace

// The golden and its sidecar for a user's own file: the criterion stated, no absolute paths.
TEST(TruthRenderer, GoldenSidecarHasBoundAndNoAbsolutePaths) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "iblcheck_truth_golden_test";
    fs::create_directories(dir);
    const fs::path envf = dir / "my_sky.exr";
    write_exr(envf.string(), load_environment("sky_sun").equirect);
    GoldenRequest req;
    req.spec = spec_of("sphere", envf.string(), 24, 24);
    req.out_exr = (dir / "golden.exr").string();
    req.command = "test";
    const GoldenWritten g = write_truth_golden(req);
    std::ifstream f(dir / "golden.json");
    const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find(dir.string()), std::string::npos) << "the sidecar holds an absolute path";
    EXPECT_EQ(g.meta["env"]["spec"], "my_sky.exr");
    EXPECT_EQ(g.meta["image"], "golden.exr");
    EXPECT_TRUE(g.meta["error_bound"]["criterion"].contains("met"));
    EXPECT_TRUE(g.meta["error_bound"].contains("mean_flip"));
    EXPECT_EQ(g.meta["deterministic"], true);
    fs::remove_all(dir);
}

// Every committed reference golden states its accuracy, and the accuracy holds (goldens are written only
// by scripts/regenerate_reference_goldens.sh, so this checks what that script produced): a quadrature
// golden meets the criterion (mean FLIP < 0.002, relative RMSE < 0.5 %); a Monte Carlo one its seed
// noise floor's; a temporal truth sequence keeps every bound frame's HDR-FLIP below 0.003 and relative
// RMSE below 2.5 % (measured: up to 0.0028 and 1.9 %; its normal table at the old tolerance, 0.1, left
// the sun's spots unresolved: 17 %).
// The temporal sequences' criterion: met only when all three bounds hold; the LDR-FLIP one (the suite's
// metric) is under 10 % of the smallest variant distance the temporal suite judges.
TEST(TruthRenderer, SequenceCriterionIsMetOnlyWhenEveryBoundHolds) {
    EXPECT_LE(kSequenceCriterionLdrFlip, 0.1 * kSmallestJudgedLdrFlip);
    const nlohmann::json ok = sequence_criterion(0.0018, 0.0028, 0.0188); // sphere_field's 2026-11-26 figures
    EXPECT_TRUE(ok.at("met").get<bool>());
    EXPECT_FALSE(ok.at("still_golden_criterion").at("met").get<bool>()); // 1.88 % > 0.5 %: stated, not hidden
    EXPECT_FALSE(ok.at("still_golden_criterion").at("relative_rmse_met").get<bool>());
    EXPECT_EQ(ok.at("relied_on").get<std::string>(), "mean_flip_ldr");
    const nlohmann::json ldr = sequence_criterion(0.0021, 0.0010, 0.001);
    EXPECT_FALSE(ldr.at("mean_flip_ldr_met").get<bool>());
    EXPECT_FALSE(ldr.at("met").get<bool>());
    EXPECT_FALSE(sequence_criterion(0.0010, 0.0031, 0.001).at("met").get<bool>());
    EXPECT_FALSE(sequence_criterion(0.0010, 0.0010, 0.026).at("met").get<bool>());
}

TEST(TruthRenderer, CommittedReferenceGoldensStateABoundThatHolds) {
    namespace fs = std::filesystem;
    int quadrature = 0, monte_carlo = 0, sequences = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(IBLCHECK_SOURCE_DIR) / "goldens" / "reference")) {
        if (entry.path().extension() != ".json") continue;
        std::ifstream f(entry.path());
        const nlohmann::json m = nlohmann::json::parse(f);
        const std::string name = entry.path().filename().string();
        ASSERT_TRUE(fs::exists(fs::path(entry.path()).replace_extension(".exr"))) << name;
        if (name.find("__frames=") != std::string::npos) {
            // Every reference sidecar records its criterion as met (issue 28), the sequences included: the sequence
            // criterion is truth::sequence_criterion's (LDR-FLIP relied on, HDR-FLIP and relative RMSE bounded).
            const auto& b = m.at("error_bound");
            ASSERT_TRUE(b.contains("criterion")) << name << ": a sequence without a criterion";
            EXPECT_TRUE(b.at("criterion").at("met").get<bool>()) << name;
            EXPECT_LT(b.at("mean_flip_ldr_max").get<double>(), b.at("criterion").at("mean_flip_ldr_below").get<double>()) << name;
            ++sequences;
        } else if (m.value("integrator", "") == "quadrature") {
            EXPECT_TRUE(m.at("error_bound").at("criterion").at("met").get<bool>()) << name;
            ++quadrature;
        } else {
            EXPECT_TRUE(m.at("noise_floor").at("criterion").at("met").get<bool>()) << name;
            ++monte_carlo;
        }
    }
    EXPECT_EQ(quadrature, 8);
    EXPECT_EQ(monte_carlo, 1);
    EXPECT_EQ(sequences, 3);
}
} // namespace test_truth_golden
