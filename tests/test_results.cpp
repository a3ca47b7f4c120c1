// The typed results (results/results.h): what to_json writes is what fields() lists, what the format
// page documents, and what from_json reads back; the reader checks each key's type from fields().
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "kernel/errors.h"
#include "metrics/catalog.h"
#include "results/results.h"
#include "results/results_file.h"

using namespace iblcheck;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_results {

namespace {

std::set<std::string> field_keys(ResultsObject object) {
    std::set<std::string> keys;
    for (const Field& f : fields(object)) keys.insert(f.key);
    return keys;
}

std::set<std::string> keys_of(const json& j) {
    std::set<std::string> keys;
    for (auto& [k, v] : j.items()) keys.insert(k);
    return keys;
}

// The keys in the first column of the table under `## <heading>` in RESULTS_FORMAT.md ("`a`, `b`").
std::set<std::string> page_keys(const std::string& heading) {
    std::ifstream in(std::string(IBLCHECK_SOURCE_DIR) + "/results/RESULTS_FORMAT.md");
    std::set<std::string> keys;
    bool inside = false;
    const std::regex key("`([a-z_]+)`");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("## ", 0) == 0) inside = line == "## " + heading;
        if (!inside || line.rfind("| `", 0) != 0) continue;
        const std::string cell = line.substr(1, line.find('|', 1) - 1);
        for (std::sregex_iterator it(cell.begin(), cell.end(), key), end; it != end; ++it) keys.insert((*it)[1]);
    }
    return keys;
}

Check full_check() { return {"flip.mean", 0.25, 0.0, 0.5, 0.2, Verdict::improved, "flip.mean improved"}; }

Comparison full_comparison() {
    Comparison c;
    c.kind = "baseline";
    c.golden = "baseline/t.exr";
    c.label = "lavapipe";
    c.metrics = {{"flip", {{"mean", 0.25}}}};
    c.checks = {full_check()};
    c.verdict = Verdict::fail;
    c.message = "flip.mean 0.25 > 0.001";
    c.images = {{"test", "images/t/test.png"}};
    c.worst_block = WorstBlock{16, 32, 0.5, "flip", "metal r=0.3"};
    c.approved = {{"commit", "abc1234"}};
    return c;
}

TestResult full_test() {
    TestResult t;
    t.name = "mobile.spheres.studio";
    t.suite = "ci";
    t.scene = "spheres";
    t.method = "mobile";
    t.env = "studio";
    t.options = {{"samples", "128"}};
    t.variant = "default";
    t.display = {{"tonemap", "aces"}};
    t.tags = {"fast"};
    t.bless_command = "iblcheck bless --suite ci --filter mobile.spheres.studio";
    RenderFigures r;
    r.width = 64;
    r.height = 32;
    r.timings = {{"shade", 1.5, true, false}};
    r.precompute_ms = 2;
    r.frame_ms = 1.5;
    r.frame_ms_samples = {1.5, 1.6};
    r.timing_group = "mobile.spheres.*.default";
    r.texture_fetches_per_pixel = 7;
    r.texture_bytes = 4096;
    r.texel_count = 1024;
    r.cost = {{"texture_fetches_per_pixel", 7}};
    r.provenance = {{"method", "mobile"}};
    t.render = r;
    t.image = "images/t/test.png";
    t.image_exr = "images/t/test.exr";
    t.layout = json{{"id_map", "images/t/ids.png"}};
    t.comparisons = {full_comparison()};
    t.accuracy = Accuracy{0.1, 0.9, "reference/t.exr", json{{"mean_flip", 0.001}},
                          DisplayAccuracy{json{{"tonemap", "aces"}}, 0.05, 0.95, 31.5}};
    t.driver_mismatch = "golden blessed on another platform: CPU class a -> b";
    t.per_sphere = json::array({{{"label", "metal r=0"}, {"roughness", 0}, {"flip_mean", 0.1}}});
    t.furnace = json{{"worst", 0.1}};
    t.temporal = json{{"flicker", 0.01}};
    t.stability = json{{"flaky", false}};
    t.verdict = Verdict::fail;
    t.message = "baseline: flip.mean 0.25 > 0.001";
    t.wall_s = 0.5;
    t.profile = json{{"shading", 0.1}};
    return t;
}

RunResults full_run() {
    RunResults r;
    r.suite = "ci";
    r.command = "iblcheck run --suite ci";
    r.started = "2026-11-26T22:00:00Z";
    r.total_s = 12.5;
    r.commit = "abc1234";
    r.dirty = true;
    r.driver = {{"device", "llvmpipe"}};
    r.cpu_features = json::array({"avx2"});
    r.cpu_class = "avx2-fma-f16c-256";
    r.shard = "0/1";
    r.tests = {full_test()};
    return r;
}

} // namespace

// A key written but not documented, or documented but not written, fails here: the page's tables
// and the types' fields() are the same lists.
TEST(Results, TheFormatPageDocumentsEveryFieldOfTheTypes) {
    EXPECT_EQ(page_keys("Top level"), field_keys(ResultsObject::run));
    EXPECT_EQ(page_keys("Test"), field_keys(ResultsObject::test));
    EXPECT_EQ(page_keys("Comparison"), field_keys(ResultsObject::comparison));
    EXPECT_EQ(page_keys("Check"), field_keys(ResultsObject::check));
}

// Every member of the types set: to_json writes exactly the keys fields() lists (a member added to a
// type must be written in to_json, which does not compile until it names it, and so lands here).
TEST(Results, ToJsonWritesExactlyTheKeysFieldsLists) {
    const json run = to_json(full_run());
    std::set<std::string> run_keys = field_keys(ResultsObject::run);
    run_keys.erase("shards"); // written by `iblcheck report` when it merges the shards of a run
    EXPECT_EQ(keys_of(run), run_keys);
    EXPECT_EQ(keys_of(run["tests"][0]), field_keys(ResultsObject::test));
    EXPECT_EQ(keys_of(run["tests"][0]["comparisons"][0]), field_keys(ResultsObject::comparison));
    EXPECT_EQ(keys_of(run["tests"][0]["comparisons"][0]["checks"][0]), field_keys(ResultsObject::check));
    EXPECT_EQ(run["counts"], json({{"pass", 0}, {"fail", 1}, {"improved", 0}, {"missing-golden", 0}, {"error", 0}}));
    EXPECT_EQ(run["schema"], "iblcheck-results/1");
}

// What is written reads back the same, nulls and absent keys included; and the reader accepts it.
TEST(Results, FromJsonReadsBackWhatToJsonWrote) {
    const json full = to_json(full_run());
    EXPECT_EQ(to_json(full.get<RunResults>()), full);
    EXPECT_NO_THROW(results::validate_results(full, "full.json"));
    TestResult bare; // a test stopped before its render: no figures, accuracy and driver_mismatch null
    bare.name = "t";
    bare.verdict = Verdict::error;
    const json j = to_json(bare);
    EXPECT_TRUE(j.contains("accuracy") && j["accuracy"].is_null());
    EXPECT_TRUE(j.contains("driver_mismatch") && j["driver_mismatch"].is_null());
    EXPECT_FALSE(j.contains("width"));
    EXPECT_FALSE(j.contains("image"));
    EXPECT_EQ(j["verdict"], "error");
    EXPECT_EQ(to_json(j.get<TestResult>()), j);
    // NaN (SSIM of an image under its window) is null in the JSON and reads back as NaN.
    TestResult nan = full_test();
    nan.accuracy->ssim = std::nan("");
    EXPECT_TRUE(to_json(nan)["accuracy"]["ssim"].is_null());
    EXPECT_TRUE(std::isnan(to_json(nan).get<TestResult>().accuracy->ssim));
}

// The accuracy summary's figures are the metric catalog's, by the catalog's names (accuracy_name):
// each judged metric that has one is written there with the value of its own field, and the summary
// holds no other figure. A name added to the catalog but not written, or written under another
// name, fails here.
TEST(Results, TheAccuracySummaryHoldsTheCatalogsFiguresByTheirNames) {
    const TestResult t = full_test();
    const Accuracy& a = *t.accuracy;
    const json j = to_json(t)["accuracy"];
    const std::map<std::string, double> value = {{"flip.mean", a.flip_mean},
                                                 {"ssim.mean", a.ssim},
                                                 {"display_flip.mean", a.display->flip_mean},
                                                 {"display_ssim.mean", a.display->ssim},
                                                 {"display_psnr.db", a.display->psnr_db}};
    std::set<std::string> linear, display;
    for (const MetricInfo* k : judged_metrics(true)) {
        if (!*k->accuracy_name) continue;
        const bool shown = k->space == MetricSpace::test_display;
        (shown ? display : linear).insert(k->accuracy_name);
        const json& where = shown ? j["display"] : j;
        ASSERT_TRUE(where.contains(k->accuracy_name)) << k->key << " as " << k->accuracy_name;
        ASSERT_TRUE(value.count(k->key)) << k->key << ": a summary figure this test does not know";
        EXPECT_EQ(where[k->accuracy_name].get<double>(), value.at(k->key)) << k->key;
    }
    std::set<std::string> written, written_display;
    for (const auto& [key, v] : j.items())
        if (v.is_number()) written.insert(key);
    for (const auto& [key, v] : j["display"].items())
        if (v.is_number()) written_display.insert(key);
    EXPECT_EQ(written, linear);
    EXPECT_EQ(written_display, display);
    EXPECT_EQ(written.size(), 2u);
    EXPECT_EQ(written_display.size(), 3u);
}

// The reader checks every key fields() marks checked by its type, and names it.
TEST(Results, TheReaderChecksEachCheckedKeyByItsFieldType) {
    const json full = to_json(full_run());
    auto wrong_value = [](JsonType type) { return type == JsonType::string ? json(1) : json("x"); };
    auto expect_refused = [](const json& doc, const std::string& key) {
        try {
            results::validate_results(doc, "r.json");
            ADD_FAILURE() << key << " of the wrong type was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("'" + key + "' must be"), std::string::npos) << e.what();
        }
    };
    int checked = 0;
    for (const Field& f : fields(ResultsObject::test)) {
        if (!f.checked) continue;
        json doc = full;
        doc["tests"][0][f.key] = wrong_value(f.type);
        expect_refused(doc, f.key);
        ++checked;
    }
    for (const Field& f : fields(ResultsObject::comparison)) {
        if (!f.checked) continue;
        json doc = full;
        doc["tests"][0]["comparisons"][0][f.key] = wrong_value(f.type);
        expect_refused(doc, f.key);
        ++checked;
    }
    for (const Field& f : fields(ResultsObject::check)) {
        if (!f.checked) continue;
        json doc = full;
        doc["tests"][0]["comparisons"][0]["checks"][0][f.key] = wrong_value(f.type);
        expect_refused(doc, f.key);
        ++checked;
    }
    EXPECT_GT(checked, 40);
}
} // namespace test_results
