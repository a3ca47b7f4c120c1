// A suite sharded over machines merges into one report (issue 29): four `run --shard i/4` of ci tests
// merged by `iblcheck report` give the same tests, verdicts and figures, and the same JUnit (times
// aside), as one unsharded run; shards of another commit or suite, a missing shard and an overlapping
// one are refused (exit 2, naming the files and the field). Four cheap ci tests (the white furnace,
// one a shard) against a golden copy without one baseline, so a missing-golden verdict is merged too.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_report_shards {

namespace {

const std::string kCli = testutil::built("iblcheck");
const std::vector<std::string> kTests = {"mobile.furnace.constant:1.default", "mobile.furnace.constant:1.env_brdf=lut",
                                         "mobile.furnace_dielectric.constant:1.default",
                                         "mobile.furnace.constant:1.normalization=directional"};

json read_json(const fs::path& p) { return json::parse(testutil::read_text(p)); }

// JUnit without its times (wall clock) and timestamp.
std::string without_times(const std::string& xml) {
    return std::regex_replace(xml, std::regex(R"( (time|timestamp)="[^"]*")"), "");
}

class ReportShards : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = testutil::temp_dir("report_shards");
        const fs::path src = fs::path(IBLCHECK_SOURCE_DIR) / "goldens";
        fs::create_directories(dir_ / "g");
        fs::copy(src / "reference", dir_ / "g/reference", fs::copy_options::recursive);
        fs::create_directories(dir_ / "g/baseline");
        for (size_t k = 0; k + 1 < kTests.size(); ++k) // the last test has no baseline here: missing-golden
            for (const char* ext : {".exr", ".json"}) {
                std::string f = kTests[k];
                std::replace(f.begin(), f.end(), ':', '-');
                fs::copy(src / "baseline" / (f + ext), dir_ / "g/baseline" / (f + ext));
            }
        for (const auto& t : kTests) filter_ += (filter_.empty() ? "" : "|") + t;
    }
    void TearDown() override { fs::remove_all(dir_); }
    int cli(const std::string& args, std::string& out) const {
        return testutil::run_command("cd " + dir_.string() + " && " + kCli + " " + args, out);
    }
    int run(const std::string& extra, std::string& out) const {
        return cli("run --suite ci --goldens g -q --filter '" + filter_ + "' " + extra, out);
    }
    std::string shards(const std::vector<int>& which) const {
        std::string s;
        for (int i : which) s += " s" + std::to_string(i) + "/results.json";
        return s;
    }
    fs::path dir_;
    std::string filter_;
};

TEST_F(ReportShards, FourShardsMergeIntoTheVerdictsAndJUnitOfOneUnshardedRun) {
    std::string out;
    ASSERT_EQ(run("--out all --junit all.xml", out), 1) << out; // 3 pass, 1 missing-golden
    for (int i = 0; i < 4; ++i)
        ASSERT_EQ(run("--out s" + std::to_string(i) + " --shard " + std::to_string(i) + "/4", out) < 2, true) << out;
    ASSERT_EQ(cli("report" + shards({0, 1, 2, 3}) + " --out merged --junit merged.xml", out), 0) << out;
    EXPECT_NE(out.find("(4 shards merged: 4 tests)"), std::string::npos) << out;
    const json all = read_json(dir_ / "all/results.json"), merged = read_json(dir_ / "merged/results.json");
    EXPECT_EQ(merged["counts"], all["counts"]);
    EXPECT_EQ(all["counts"]["missing-golden"], 1);
    ASSERT_EQ(merged["tests"].size(), all["tests"].size());
    for (size_t k = 0; k < all["tests"].size(); ++k) {
        const json &a = all["tests"][k], &m = merged["tests"][k];
        EXPECT_EQ(m["name"], a["name"]) << k; // the suite's order
        EXPECT_EQ(m["verdict"], a["verdict"]) << a["name"];
        EXPECT_EQ(m["comparisons"], a["comparisons"]) << a["name"]; // every figure, bound and image
        EXPECT_EQ(m["accuracy"], a["accuracy"]) << a["name"];
        EXPECT_EQ(m["message"], a["message"]) << a["name"];
    }
    EXPECT_EQ(merged["shard"], "0/1");
    EXPECT_EQ(merged["shards"].size(), 4u);
    EXPECT_EQ(merged["command"].get<std::string>().find("--shard"), std::string::npos) << merged["command"];
    EXPECT_EQ(without_times(testutil::read_text(dir_ / "merged.xml")), without_times(testutil::read_text(dir_ / "all.xml")));
    // The report shows every test with its images, copied from the shards' folders.
    const std::string html = testutil::read_text(dir_ / "merged/index.html");
    for (const auto& t : kTests) EXPECT_NE(html.find(t), std::string::npos) << t;
    EXPECT_TRUE(fs::exists(dir_ / "merged/images/mobile.furnace.constant-1.env_brdf=lut/test.png"));

    // Refused, exit 2, naming the files and the field: a missing shard, one given twice, another
    // commit, another suite.
    EXPECT_EQ(cli("report" + shards({0, 1, 3}) + " --out m1", out), 2) << out;
    EXPECT_NE(out.find("shard(s) 2/4 missing"), std::string::npos) << out;
    EXPECT_EQ(cli("report" + shards({0, 1, 1, 2, 3}) + " --out m2", out), 2) << out;
    EXPECT_NE(out.find("s1/results.json and s1/results.json: both are shard 1/4 (field \"shard\")"), std::string::npos) << out;
    for (const auto& [field, value] :
         std::vector<std::pair<std::string, std::string>>{{"commit", "0123456789ab"}, {"suite", "nightly"}}) {
        json other = read_json(dir_ / "s3/results.json");
        other[field] = value;
        testutil::write_file(dir_ / "s3/results.json", other.dump());
        EXPECT_EQ(cli("report" + shards({0, 1, 2, 3}) + " --out m3", out), 2) << out;
        EXPECT_NE(out.find("s0/results.json and s3/results.json: shards of different"), std::string::npos) << out;
        EXPECT_NE(out.find("(field \"" + field + "\": "), std::string::npos) << out;
        EXPECT_FALSE(fs::exists(dir_ / "m3/index.html"));
    }
}

} // namespace
} // namespace test_report_shards
