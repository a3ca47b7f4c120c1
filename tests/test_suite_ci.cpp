// The `ci` suite as individual CTest tests: one GoogleTest case per suite test, registered at run
// time from harness/suites/ci.json (so gtest_discover_tests lists them). Each case runs that one
// test through the harness and fails with the harness's message unless the verdict is pass (or
// improved).
//
// Three ways this form used to pass without testing anything, each closed here:
//  * GoogleTest splits --gtest_filter on ':' (and '-' starts the negative patterns), so a case
//    named after "constant:1" matched nothing. Case names are the test names with every character
//    outside [A-Za-z0-9_.=,] replaced by '_'; the case keeps the real name.
//  * A process that runs zero tests exits 0. Here it exits 1 ("ran no test").
//  * GTEST_SHARD_INDEX/GTEST_TOTAL_SHARDS made GoogleTest shard the ONE test that CTest's filter
//    selects: shards > 0 ran nothing and passed. This main reads the variables itself, removes them
//    before GoogleTest sees them, and shards the suite as `iblcheck run --shard` does: a test of
//    another shard is reported SKIPPED (CTest shows "Skipped", not "Passed").
#include <gtest/gtest.h>

#include <cstdlib>

#include "harness/runner.h"
#include "harness/suite.h"

using namespace iblcheck;

namespace {
class SuiteTest : public testing::Test {
  public:
    SuiteTest(std::string name, bool in_shard, std::string shard)
        : name_(std::move(name)), in_shard_(in_shard), shard_(std::move(shard)) {}
    void TestBody() override {
        if (!in_shard_) GTEST_SKIP() << name_ << " runs in another shard (this is shard " << shard_ << ")";
        RunOptions o;
        o.suite = "ci";
        o.filter = name_;
        o.quiet = true;
        o.jobs = 1;
        RunSummary s = run_suite(o);
        ASSERT_EQ(s.results["tests"].size(), 1u);
        const auto& t = s.results["tests"][0];
        std::string verdict = t["verdict"];
        EXPECT_TRUE(verdict == "pass" || verdict == "improved")
            << verdict << ": " << t["message"].get<std::string>() << "\n  rebless: " << t["bless_command"].get<std::string>();
    }

  private:
    std::string name_;
    bool in_shard_;
    std::string shard_;
};

std::string gtest_safe(const std::string& name) {
    std::string s = name;
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.' && c != '=' && c != ',') c = '_';
    return s;
}

int env_int(const char* name, int fallback) {
    const char* v = std::getenv(name);
    return v && *v ? std::atoi(v) : fallback;
}
} // namespace

int main(int argc, char** argv) {
    // Read and remove the sharding variables before GoogleTest reads them (single-threaded here).
    const int shard_count = env_int("GTEST_TOTAL_SHARDS", 1), shard_index = env_int("GTEST_SHARD_INDEX", 0);
    unsetenv("GTEST_TOTAL_SHARDS");
    unsetenv("GTEST_SHARD_INDEX");
    testing::InitGoogleTest(&argc, argv);
    if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count) {
        fprintf(stderr, "error: GTEST_SHARD_INDEX=%d is not in 0..GTEST_TOTAL_SHARDS-1 (%d)\n", shard_index, shard_count - 1);
        return 1;
    }
    Suite suite = load_suite("ci");
    std::set<std::string> mine;
    for (const auto& t : select_tests(suite, "", shard_index, shard_count)) mine.insert(t.name);
    const std::string shard = std::to_string(shard_index) + "/" + std::to_string(shard_count);
    for (const auto& t : suite.tests) {
        std::string name = t.name;
        bool in_shard = mine.count(name) > 0;
        testing::RegisterTest("ci", gtest_safe(name).c_str(), nullptr, nullptr, __FILE__, __LINE__,
                              [name, in_shard, shard]() -> testing::Test* { return new SuiteTest(name, in_shard, shard); });
    }
    int rc = RUN_ALL_TESTS();
    if (testing::UnitTest::GetInstance()->test_to_run_count() == 0) {
        fprintf(stderr, "error: ran no test (the filter matched none of the ci suite's tests)\n");
        return 1;
    }
    return rc;
}
