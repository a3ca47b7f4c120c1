// The metric catalog (metrics/catalog.h) against the comparison it describes (metrics/image_compare.h):
// every key it lists is a number where it says, and the lists read from it hold what they should.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "metrics/catalog.h"
#include "metrics/image_compare.h"
#include "tests/synthetic_image.h"

using namespace iblcheck;
using iblcheck::testing_support::synthetic;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_metric_catalog {

namespace {

// A display test's comparison of two different HDR images, with `compare`'s linear PSNR too: every
// group the catalog can name.
nlohmann::json every_group() {
    const cv::Mat a = synthetic(32, 24, 3, 0.02f) * 3.0, b = synthetic(32, 24, 4, 0.1f) * 3.0;
    static const DisplaySpace display{DisplayTonemap::pbr_neutral, 0.5, DisplayQuantize::srgb8, RenderTarget::rgba16f};
    CompareOptions o;
    o.flip_options.threads = 1;
    o.linear_psnr = true;
    o.display = &display;
    return compare_images(a, b, o);
}

} // namespace

// A catalog entry names a figure the comparison computes: a key added without its computation (or
// pointing at the wrong group or field) fails here.
TEST(MetricCatalog, EveryKeyIsANumberOfTheComparison) {
    const nlohmann::json m = every_group();
    std::set<std::string> keys;
    for (const MetricInfo& k : metric_catalog()) {
        EXPECT_TRUE(keys.insert(k.key).second) << k.key << " twice";
        EXPECT_EQ(std::string(k.key), std::string(k.group) + "." + k.field);
        ASSERT_TRUE(m.contains(k.group) && m[k.group].contains(k.field)) << k.key;
        EXPECT_TRUE(m[k.group][k.field].is_number()) << k.key << ": " << m[k.group].dump();
        EXPECT_NE(std::string(k.computed_by), "") << k.key;
    }
    EXPECT_EQ(find_metric("flip.mean"), &metric("flip.mean"));
    EXPECT_EQ(find_metric("flip_mean"), nullptr); // the summary's name is not a key
    EXPECT_THROW(metric("lpips.mean"), std::logic_error);
}

// The harness's comparison (no display space, no linear PSNR) gives exactly the judged linear keys'
// groups; a display space adds the display ones; linear_psnr is `compare`'s alone.
TEST(MetricCatalog, JudgedKeysAreWhatTheRunnerComputes) {
    const cv::Mat a = synthetic(16, 16, 5, 0.0f), b = synthetic(16, 16, 6, 0.1f);
    const nlohmann::json m = compare_images(a, b, 1);
    for (const MetricInfo* k : judged_metrics(false)) EXPECT_TRUE(m[k->group][k->field].is_number()) << k->key;
    for (const MetricInfo* k : judged_metrics(true))
        EXPECT_EQ(m.contains(k->group), k->space != MetricSpace::test_display) << k->key;
    EXPECT_FALSE(m.contains("linear_psnr"));
    const std::set<std::string> judged = judged_metric_keys();
    EXPECT_EQ(judged.size(), judged_metrics(true).size());
    EXPECT_TRUE(judged.count("display_psnr.db"));
    EXPECT_FALSE(judged.count("linear_psnr.db")); // not judged: a suite may not bound it
}

// Each summary name appears once in its object (the accuracy object, or its "display" object), and
// floor_distance is 0 for a perfect score in either direction.
TEST(MetricCatalog, SummaryNamesAreUniqueAndFloorsStartAtZero) {
    std::set<std::string> linear, display;
    for (const MetricInfo* k : judged_metrics(true)) {
        if (!*k->accuracy_name) continue;
        EXPECT_TRUE((k->space == MetricSpace::test_display ? display : linear).insert(k->accuracy_name).second) << k->key;
    }
    EXPECT_EQ(linear, (std::set<std::string>{"flip_mean", "ssim"}));
    EXPECT_EQ(display, (std::set<std::string>{"flip_mean", "psnr_db", "ssim"}));
    EXPECT_EQ(floor_distance(metric("flip.mean"), 0.0), 0.0);
    EXPECT_EQ(floor_distance(metric("ssim.mean"), 1.0), 0.0);
    EXPECT_EQ(floor_distance(metric("display_ssim.mean"), 0.75), 0.25);
}
} // namespace test_metric_catalog
