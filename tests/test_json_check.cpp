// The shared JSON checker (kernel/json_check.h): every error names the file, where in it,
// and the problem with the type actually found.
#include <gtest/gtest.h>

#include "kernel/errors.h"
#include "kernel/json_check.h"
#include "tests/test_support.h"

using namespace iblcheck;
using nlohmann::json;

using testutil::input_error_of;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_json_check {

TEST(JsonChecker, FailNamesFileWhereAndProblem) {
    const JsonChecker c("suites/x.json");
    EXPECT_EQ(input_error_of([&] { c.fail("tests[2].size", "'big' is not WxH"); }),
              "suites/x.json: tests[2].size: 'big' is not WxH");
    EXPECT_EQ(input_error_of([&] { c.fail("", "not an object"); }), "suites/x.json: not an object");
}

TEST(JsonChecker, ValuesMustHaveTheirTypeAndSayWhatTheyAre) {
    const JsonChecker c("f.json");
    EXPECT_EQ(c.str(json("a"), "w"), "a");
    EXPECT_EQ(c.num(json(2.5), "w"), 2.5);
    EXPECT_EQ(c.num(json(3), "w"), 3.0);
    EXPECT_TRUE(c.boolean(json(true), "w"));
    EXPECT_EQ(input_error_of([&] { c.str(json(1), "tests[0].env"); }), "f.json: tests[0].env: must be a string, not number");
    EXPECT_EQ(input_error_of([&] { c.num(json("1"), "jobs"); }), "f.json: jobs: must be a number, not string");
    EXPECT_EQ(input_error_of([&] { c.boolean(json(1), "baseline"); }), "f.json: baseline: must be true or false, not number");
}

TEST(JsonChecker, KeysListTheValidOnes) {
    const JsonChecker c("f.json");
    EXPECT_NO_THROW(c.keys(json{{"min", 1}}, "b", {"min", "max"}));
    EXPECT_EQ(input_error_of([&] {
                  c.keys(json{{"maximum", 1}}, "b", {"min", "max"});
              }),
              "f.json: b.maximum: unknown key; valid: max, min");
    EXPECT_EQ(input_error_of([&] { c.keys(json::array(), "b", {"min"}); }), "f.json: b: must be an object, not array");
}

TEST(JsonChecker, MembersAreOptionalUnlessRequiredAndTyped) {
    const JsonChecker c("r.json");
    const json obj = {{"ms", 4.0}, {"name", "x"}, {"gone", nullptr}, {"list", json::array({1})}};
    ASSERT_NE(c.member(obj, "t", "ms", JsonType::number), nullptr);
    EXPECT_EQ(c.member(obj, "t", "ms", JsonType::number)->get<double>(), 4.0);
    EXPECT_EQ(c.member(obj, "t", "absent", JsonType::string), nullptr);
    EXPECT_EQ(c.member(obj, "t", "gone", JsonType::object), nullptr); // null counts as absent
    EXPECT_NE(c.member(obj, "t", "list", JsonType::array), nullptr);
    EXPECT_EQ(input_error_of([&] { c.member(obj, "t", "absent", JsonType::string, true); }), "r.json: t: missing key 'absent'");
    EXPECT_EQ(input_error_of([&] { c.member(obj, "t", "name", JsonType::number); }),
              "r.json: t: 'name' must be a number, not string");
    EXPECT_EQ(input_error_of([&] { c.member(obj, "t", "ms", JsonType::boolean); }),
              "r.json: t: 'ms' must be true or false, not number");
    EXPECT_EQ(input_error_of([&] { c.member(obj, "t", "list", JsonType::object); }),
              "r.json: t: 'list' must be an object, not array");
}
} // namespace test_json_check
