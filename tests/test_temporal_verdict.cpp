// The specular-AA verdict of a temporal run (reports/temporal_verdict.h, issue 28): from synthetic
// results, the paragraph names the variant that reduces flicker without costing FLIP vs the truth, per
// scene, and says "none" with the reason where every variant misses.
#include <gtest/gtest.h>

#include "reports/temporal_verdict.h"

using nlohmann::json;
using namespace iblcheck::report;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_temporal_verdict {

namespace {

// A temporal test of `scene` with specular_aa = aa, its truth figures and off's.
json temporal_test(const std::string& scene, const std::string& shading, const std::string& variant, double flicker, double flip,
                   double off_flicker, double off_flip) {
    json opts = {{"specular_aa", variant.substr(variant.find('=') + 1, variant.find(',') - variant.find('=') - 1)}};
    if (!shading.empty()) opts["shading"] = shading;
    return {
        {"name", "mobile." + scene + ".sky_sun." + variant},
        {"scene", scene},
        {"env", "sky_sun"},
        {"variant", variant},
        {"options", opts},
        {"temporal",
         {{"truth", {{"flicker", flicker}, {"flip_mean", flip}, {"off", {{"flicker", off_flicker}, {"flip_mean", off_flip}}}}}}}};
}

std::vector<json> synthetic_run() {
    return {
        // off itself: not a variant of the verdict
        temporal_test("sphere_field", "compute", "specular_aa=off", 0.010, 0.040, 0.010, 0.040),
        // flicker -4 %, FLIP -5 %: helps
        temporal_test("sphere_field", "compute", "specular_aa=toksvig,specular_aa_variance=0.02", 0.0096, 0.038, 0.010, 0.040),
        // flicker -15 %, FLIP +10 %: costs accuracy
        temporal_test("sphere_field", "compute", "specular_aa=tokuyoshi", 0.0085, 0.044, 0.010, 0.040),
        // flicker +20 %, FLIP +0 %: flickers more
        temporal_test("sphere_field", "compute", "specular_aa=rjump", 0.012, 0.040, 0.010, 0.040),
        // bumpy_sphere: toksvig -37 % flicker at +233 % FLIP, tokuyoshi +3 % / +315 %
        temporal_test("bumpy_sphere", "", "specular_aa=toksvig", 0.0207, 0.381, 0.0328, 0.1143),
        temporal_test("bumpy_sphere", "", "specular_aa=tokuyoshi", 0.0338, 0.474, 0.0328, 0.1143)};
}

std::vector<const json*> pointers(const std::vector<json>& v) {
    std::vector<const json*> p;
    for (const json& j : v) p.push_back(&j);
    return p;
}

} // namespace

TEST(TemporalVerdict, NamesTheVariantThatReducesFlickerWithoutCostingAccuracy) {
    const std::vector<json> run = synthetic_run();
    const std::vector<AaOutcome> o = aa_outcomes(pointers(run));
    ASSERT_EQ(o.size(), 5u); // off is not judged against itself
    EXPECT_TRUE(o[0].helps);
    EXPECT_NEAR(o[0].flicker_change, -0.04, 1e-9);
    EXPECT_NEAR(o[0].flip_change, -0.05, 1e-9);
    EXPECT_FALSE(o[1].helps); // calmer, but FLIP +10 % > 5 %
    EXPECT_FALSE(o[2].helps); // flickers more
    const std::vector<std::string> lines = aa_verdict_lines(o);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0], "sphere_field \u00b7 sky_sun \u00b7 shading=compute: specular_aa=toksvig,specular_aa_variance=0.02 "
                        "(flicker -4 %, FLIP -5 %) reduces flicker without costing accuracy; the other 2 of 3 do not.");
    EXPECT_EQ(lines[1], "bumpy_sphere \u00b7 sky_sun: none of 2 variants reduces flicker without costing accuracy. 2 of 2 "
                        "cost FLIP vs the truth (+233 % to +315 % of off's); 1 flicker as much as off or more. Flicker "
                        "falls most with specular_aa=toksvig (-37 %), at FLIP +233 %.");
}

TEST(TemporalVerdict, HtmlHasTheParagraphAndOnePanelPerSceneWithOffAtTheOrigin) {
    const std::vector<json> run = synthetic_run();
    const std::string h = aa_verdict_html(pointers(run));
    EXPECT_NE(h.find("<ul class=\"aa-verdict\">"), std::string::npos);
    EXPECT_NE(h.find("specular_aa=toksvig,specular_aa_variance=0.02 (flicker -4 %, FLIP -5 %) reduces flicker"),
              std::string::npos);
    // sphere_field: off + 3 variants; bumpy_sphere: off + 2
    EXPECT_NE(h.find("data-chart=\"aa-verdict-sphere-field-sky-sun-shading-compute\" data-points=\"4\""), std::string::npos) << h;
    EXPECT_NE(h.find("data-chart=\"aa-verdict-bumpy-sphere-sky-sun\" data-points=\"3\""), std::string::npos);
    EXPECT_EQ(aa_verdict_html({}), ""); // no temporal truth figures: no section
}
} // namespace test_temporal_verdict
