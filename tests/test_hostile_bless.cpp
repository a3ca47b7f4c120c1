// Issue 30, hostile input and faults: test names and goldens, bless (locking, flushing, --dry-run)
// and the commands printed for a person to paste. Every test here failed on the code before its fix.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "harness/bless.h"
#include "harness/golden_store.h"
#include "harness/suite.h"
#include "kernel/errors.h"
#include "kernel/shell_quote.h"
#include "reports/verdict_text.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_hostile_bless {

namespace {

const std::string& kMiniTest = kFurnaceTest;

// A suite of one furnace test (not blessed yet) and a private golden folder holding its truth.
struct Store : FurnaceStore {
    explicit Store(const std::string& name)
        : FurnaceStore(name, R"({"suite": "mini", "defaults": {"env": "constant:1",
                    "baseline_tolerances": {"flip.mean": {"max": 0.001}}},
                    "tests": [{"scene": "furnace", "method": "mobile"}]})") {}
    BlessOptions options() const { return bless_options(); }
};

std::vector<std::string> names(const Suite& s) {
    std::vector<std::string> out;
    for (const auto& t : s.tests) out.push_back(t.name);
    return out;
}

} // namespace

TEST(HostileBless, SizeIsInTheTestNameSoASmallerRenderNeverSharesCisGolden) {
    // A suite with "size": "1x1" named its test mobile.sphere.studio.default, like ci's, and bless
    // overwrote ci's golden with a 1x1 image.
    fs::path dir = temp_dir("size_name");
    write_file(dir / "tiny.json",
               R"({"suite": "tiny", "tests": [{"scene": "sphere", "method": "mobile", "size": "1x1", "measure_only": true},
        {"scene": "sphere", "method": "mobile", "size": "64x32", "variants": [{"shading": "fragment"}], "measure_only": true}]})");
    EXPECT_EQ(names(load_suite((dir / "tiny.json").string())),
              (std::vector<std::string>{"mobile.sphere.studio.size=1x1", "mobile.sphere.studio.shading=fragment,size=64x32"}));
    // The suites without a size keep their names, and so their goldens.
    const std::vector<std::string> ci = names(load_suite("ci"));
    EXPECT_NE(std::find(ci.begin(), ci.end(), "mobile.sphere.studio.default"), ci.end());
    for (const auto& n : ci) EXPECT_EQ(n.find("size="), std::string::npos) << n;
    fs::remove_all(dir);
}

TEST(HostileBless, TestsThatWouldShareAGoldenFileAreRefusedNamingBoth) {
    // "a-b.exr" and "a b.exr" are two environments, two test names and one golden file name.
    fs::path dir = temp_dir("share_golden");
    const fs::path ref = fs::path(IBLCHECK_SOURCE_DIR) / "goldens/reference/furnace__constant-1.exr";
    fs::copy(ref, dir / "a-b.exr");
    fs::copy(ref, dir / "a b.exr");
    const std::string a = (dir / "a-b.exr").string(), b = (dir / "a b.exr").string();
    write_file(dir / "s.json",
               R"({"suite": "s", "tests": [{"scene": "sphere", "method": "mobile", "env": [")" + a + R"(", ")" + b + R"("]}]})");
    try {
        load_suite((dir / "s.json").string());
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string m = e.what();
        // Named by their file names (issue 29: test names no longer hold the folder).
        EXPECT_NE(m.find("tests mobile.sphere.a-b.exr.default and mobile.sphere.a b.exr.default would share the "
                         "baseline golden"),
                  std::string::npos)
            << m;
        EXPECT_NE(m.find((dir / "s.json").string()), std::string::npos) << m;
    }
    fs::remove_all(dir);
}

TEST(HostileBless, BlessNeverOverwritesTheGoldenOfAnotherTest) {
    // Another suite's test whose name maps to the same file wrote it first: refused, exit 2.
    Store s("owner");
    ASSERT_EQ(bless(s.options()), kExitPass);
    json side = json::parse(read_text(s.sidecar()));
    side["test"] = "mobile.furnace.constant-1.default";
    GoldenStore::write_sidecar(s.baseline(), side);
    const std::string before = read_text(s.sidecar());
    EXPECT_EQ(bless(s.options()), kExitError);
    EXPECT_EQ(read_text(s.sidecar()), before);
}

TEST(HostileBless, DryRunWritesNothingAndExitsOneWhenABaselineWouldChange) {
    // A CI check: `bless --dry-run` used to exit 0 whatever it would have changed.
    Store s("dry_run");
    ASSERT_EQ(bless(s.options()), kExitPass);
    BlessOptions dry = s.options();
    dry.dry_run = true;
    EXPECT_EQ(bless(dry), kExitPass); // just blessed: nothing would change
    json side = json::parse(read_text(s.sidecar()));
    side["accuracy"]["flip.mean"] = side["accuracy"]["flip.mean"].get<double>() + 1e-5; // a stale approval
    GoldenStore::write_sidecar(s.baseline(), side);
    const std::string before = read_text(s.sidecar());
    EXPECT_EQ(bless(dry), kExitRegression);
    EXPECT_EQ(read_text(s.sidecar()), before);
}

TEST(HostileBless, ASecondBlessWaitsForTheFirstAndSaysSo) {
    // Two bless runs at once both exited 0 and left their goldens mixed.
    Store s("lock");
    const int fd = ::open(s.goldens.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); // not inherited by the child
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0); // as a running bless holds it
    FILE* p = popen(
        (built("iblcheck") + " bless --suite " + s.suite.string() + " --goldens " + s.goldens.string() + " 2>&1").c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string first;
    char buf[4096];
    if (fgets(buf, sizeof buf, p)) first = buf; // printed before it blocks on the lock
    EXPECT_NE(first.find("waiting: another iblcheck bless is writing into " + s.goldens.string()), std::string::npos) << first;
    EXPECT_FALSE(fs::exists(s.baseline())); // nothing written while the lock is held
    ::close(fd);
    std::string rest;
    while (fgets(buf, sizeof buf, p)) rest += buf;
    EXPECT_EQ(pclose(p), 0) << rest;
    EXPECT_NE(rest.find("blessed   " + kMiniTest), std::string::npos) << rest;
    EXPECT_TRUE(fs::exists(s.baseline()));
}

TEST(HostileBless, EachLineIsFlushedAsItIsWritten) {
    // Piped and killed after writing goldens, bless showed none of them: stdout was block-buffered.
    Store s("flush");
    const fs::path log = s.dir / "stdout.txt";
    std::fflush(stdout);
    const int saved = ::dup(STDOUT_FILENO);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    ::dup2(fd, STDOUT_FILENO);
    std::setvbuf(stdout, nullptr, _IOFBF, 1 << 16); // as when stdout is a pipe
    const int rc = bless(s.options());
    const std::string seen = read_text(log); // before any flush of ours: what a kill -9 would leave
    std::fflush(stdout);
    ::dup2(saved, STDOUT_FILENO);
    ::close(saved);
    ::close(fd);
    std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
    EXPECT_EQ(rc, kExitPass);
    EXPECT_NE(seen.find("blessed   " + kMiniTest + "  (new)"), std::string::npos) << seen;
}

TEST(HostileBless, PrintedCommandsAreShellQuotedAndSelectTheirTestOnly) {
    // An environment file named x';touch PWNED;'.exr made the printed bless command run
    // `touch PWNED` when pasted (terminal and the report's Copy button).
    fs::path dir = temp_dir("quote");
    const fs::path env = dir / "x';touch PWNED;'|*.exr";
    fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "goldens/reference/furnace__constant-1.exr", env);
    write_file(
        dir / "s.json",
        json{{"suite", "s"},
             {"tests", {{{"scene", "sphere"}, {"method", "mobile"}, {"env", {env.string(), "studio"}}, {"measure_only", true}}}}}
            .dump());
    const Suite suite = load_suite((dir / "s.json").string());
    const TestCase& tc = suite.tests[0];
    const std::string cmd = bless_command(tc);
    ASSERT_EQ(cmd.rfind("iblcheck ", 0), 0u) << cmd;
    // The shell sees exactly the arguments, and nothing runs.
    std::string out;
    EXPECT_EQ(run_command("cd " + dir.string() + " && printf '%s\\n' " + cmd.substr(9), out, false), 0);
    const std::string filter = glob_escape(tc.name);
    EXPECT_EQ(out, "bless\n--suite\n" + (dir / "s.json").string() + "\n--filter\n" + filter + "\n");
    EXPECT_FALSE(fs::exists(dir / "PWNED"));
    // The filter selects this test, not the other (its '|' and '*' are escaped).
    EXPECT_TRUE(glob_match(filter, tc.name));
    EXPECT_FALSE(glob_match(filter, suite.tests[1].name));
    // The "approve all" line of the terminal and the report, likewise.
    json tests = json::array({{{"name", tc.name}, {"verdict", "fail"}}, {{"name", suite.tests[1].name}, {"verdict", "fail"}}});
    const std::string all = report::rebless_all_line(tests, (dir / "s.json").string());
    const size_t at = all.find("iblcheck bless ");
    ASSERT_NE(at, std::string::npos) << all;
    EXPECT_EQ(run_command("cd " + dir.string() + " && printf '%s\\n' " + all.substr(at + 9), out, false), 0);
    const std::string both = out.substr(out.rfind("--filter\n") + 9);
    EXPECT_EQ(both, filter + "|" + glob_escape(suite.tests[1].name) + "\n");
    EXPECT_TRUE(glob_match(both.substr(0, both.size() - 1), tc.name));
    EXPECT_TRUE(glob_match(both.substr(0, both.size() - 1), suite.tests[1].name));
    EXPECT_FALSE(fs::exists(dir / "PWNED"));
    // The run's own command line (results "command", the report's Copy button) is quoted too.
    EXPECT_EQ(shell_arg("--out"), "--out");
    EXPECT_EQ(shell_arg(env.string()), shell_quote(env.string()));
    EXPECT_EQ(run_command("printf '%s' " + shell_arg(env.string()), out, false), 0);
    EXPECT_EQ(out, env.string());
    fs::remove_all(dir);
}
} // namespace test_hostile_bless
