// Failures that share a cause are grouped, each group with one short approve filter that selects
// exactly its tests (reports/failure_groups.h, issue 32).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "kernel/name_filter.h"
#include "reports/failure_groups.h"
#include "reports/verdict_text.h"

using nlohmann::json;
using namespace iblcheck::report;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_failure_groups {

namespace {

// `--filter`'s semantics: the harness's own (suite.h glob_match).
bool selects(const std::string& filter, const std::string& name) { return iblcheck::name_filter_match(filter, name); }

json failing(const std::string& name, const std::string& metric, const std::string& sphere, double mean) {
    return {
        {"name", name},
        {"verdict", "fail"},
        {"bless_command", "build/iblcheck bless --suite 'ci' --filter '" + name + "'"},
        {"provenance", {{"shader_tree_hash", "bbbbbbbbbbbbbbbb"}}},
        {"comparisons", json::array({{{"kind", "baseline"},
                                      {"verdict", "fail"},
                                      {"approved", {{"shader_tree_hash", "aaaaaaaaaaaaaaaa"}}},
                                      {"metrics", {{"flip", {{"mean", mean}}}}},
                                      {"worst_block", {{"sphere", sphere}}},
                                      {"checks", json::array({{{"metric", metric}, {"status", "fail"}, {"value", mean}}})}}})}};
}

// The ci suite's shape: 71 tests, 45 of them (the mobile ones with the UE4 mip mapping) failing one way.
json ci_like() {
    json tests = json::array();
    int k = 0;
    for (const char* env : {"studio", "sky_sun", "constant-1"})
        for (const char* v : {"default", "dominant_dir=lagarde", "env_brdf=lut", "storage=rgbm", "precision=mediump",
                              "specular_aa=on", "normalization=on", "diffuse=irradiance_cube", "shading=fragment",
                              "mip_mapping=filament", "mip_mapping=origin", "env_layout=equirect"})
            for (const char* m : {"mobile", "sampled"}) {
                const std::string name = fmt::format("{}.roughness_sweep.{}.{}", m, env, v);
                const bool fails = std::string(m) == "mobile" && std::string(v).find("mip_mapping") == std::string::npos;
                if (fails && k++ < 45)
                    tests.push_back(failing(name, "flip.mean", k % 2 ? "metal r=0.3" : "metal r=0.4", 0.01 + 0.001 * k));
                else
                    tests.push_back({{"name", name}, {"verdict", "pass"}});
            }
    return tests;
}

std::vector<const json*> pointers(const json& a) {
    std::vector<const json*> p;
    for (const json& t : a) p.push_back(&t);
    return p;
}

} // namespace

TEST(FailureGroups, OneCauseIsOneGroupWithAShortFilterThatSelectsExactlyItsTests) {
    const json tests = ci_like();
    const auto groups = group_failures(pointers(tests), true);
    ASSERT_EQ(groups.size(), 1u);
    const FailureGroup& g = groups[0];
    ASSERT_EQ(g.members.size(), 30u); // the mobile tests without a mip_mapping option: 3 envs x 10
    EXPECT_EQ(g.checks, "baseline");
    EXPECT_EQ(g.metrics, (std::vector<std::string>{"baseline flip.mean (30)"}));
    EXPECT_EQ(g.shader_change, "shader tree aaaaaaaa -> bbbbbbbb");
    EXPECT_EQ(g.spheres, (std::vector<std::string>{"metal r=0.3 (15)", "metal r=0.4 (15)"}));
    // The representative: the largest change against its baseline.
    EXPECT_EQ(tests[g.members[0]]["name"], "mobile.roughness_sweep.constant-1.env_layout=equirect");
    for (const json& t : tests)
        EXPECT_EQ(selects(g.filter, t["name"]), t["verdict"] == "fail") << g.filter << " and " << t["name"];
    EXPECT_EQ(g.filter, "mobile.*|!*mip_mapping=*");
    const std::string line = group_bless_line(pointers(tests), g, "ci", "");
    EXPECT_EQ(line.rfind("approve 30 failures (after looking at them): build/iblcheck bless --suite 'ci' --filter '", 0), 0u)
        << line;
    EXPECT_LT(line.size(), 300u) << line;
    // The approve-all line of a whole-suite run uses the same globs; of a partial run it spells the names out.
    EXPECT_EQ(rebless_all_line(tests, "ci", "", true), line.substr(0, 7) + " all" + line.substr(7));
    EXPECT_GT(rebless_all_line(tests, "ci", "", false).size(), 1000u);
}

TEST(FailureGroups, DifferentChecksOrShaderChangesAreDifferentGroups) {
    json tests =
        json::array({failing("mobile.a.studio.default", "flip.mean", "metal r=0.3", 0.02),
                     failing("mobile.a.sky_sun.default", "flip.mean", "metal r=0.3", 0.03),
                     failing("mobile.b.studio.default", "flip.p99", "metal r=0.3", 0.04),
                     {{"name", "mobile.c.studio.default"}, {"verdict", "error"}, {"message", "render failed: 3 NaN pixels"}},
                     {{"name", "mobile.d.studio.default"}, {"verdict", "pass"}}});
    // Per-file shader hashes, where both sides have them, name the file that changed.
    tests[2]["provenance"]["shader_files"] = {{"mip_mapping.glsl", "2"}, {"brdf.glsl", "1"}};
    tests[2]["comparisons"][0]["approved"]["shader_files"] = {{"mip_mapping.glsl", "1"}, {"brdf.glsl", "1"}};
    const auto groups = group_failures(pointers(tests), true);
    ASSERT_EQ(groups.size(), 3u);
    // Same comparison failing, different metric: still one cause (not split); another shader change: another.
    EXPECT_EQ(groups[0].members, (std::vector<size_t>{1, 0})); // largest first, the larger change representing it
    EXPECT_EQ(groups[0].filter, "mobile.a.*");                 // the fewest '*', then the shortest
    EXPECT_EQ(groups[1].shader_change, "mip_mapping.glsl changed");
    EXPECT_EQ(groups[1].filter, "mobile.b.studio.default"); // a group of one: its name
    EXPECT_EQ(groups[2].verdict, "error");
    EXPECT_EQ(groups[2].checks, "render failed: ");
    EXPECT_EQ(group_bless_line(pointers(tests), groups[2], "ci", ""), ""); // an error is not approved
    // A run with --filter: the suite may hold other tests a glob would catch; the names are spelt out.
    EXPECT_EQ(group_failures(pointers(tests), false)[0].filter, "mobile.a.sky_sun.default|mobile.a.studio.default");
    EXPECT_TRUE(ran_whole_suite({{"command", "iblcheck run --suite ci"}}));
    EXPECT_FALSE(ran_whole_suite({{"command", "iblcheck run --suite ci --filter '*lagarde*'"}}));
    EXPECT_FALSE(ran_whole_suite({{"command", "iblcheck run --suite ci --shard 1/3"}}));
}
} // namespace test_failure_groups
