// The `ci` suite as individual CTest tests: one GoogleTest case per suite test, registered at run
// time from harness/suites/ci.json (so gtest_discover_tests lists them, and GTEST_SHARD_INDEX /
// GTEST_TOTAL_SHARDS spread them over machines). Each case runs that one test through the harness
// and fails with the harness's message unless the verdict is pass (or improved).
#include <gtest/gtest.h>

#include "harness/runner.h"
#include "harness/suite.h"

using namespace iblcheck;

namespace {
class SuiteTest : public testing::Test {
  public:
    explicit SuiteTest(std::string name) : name_(std::move(name)) {}
    void TestBody() override {
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
};
} // namespace

int main(int argc, char** argv) {
    testing::InitGoogleTest(&argc, argv);
    Suite suite = load_suite("ci");
    for (const auto& t : suite.tests) {
        std::string name = t.name;
        testing::RegisterTest("ci", name.c_str(), nullptr, nullptr, __FILE__, __LINE__,
                              [name]() -> testing::Test* { return new SuiteTest(name); });
    }
    return RUN_ALL_TESTS();
}
