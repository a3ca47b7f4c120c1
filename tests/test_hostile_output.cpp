// Issue 30, hostile input and faults: what the commands write. Nothing is overwritten without
// --force, an output is never an input, a run's --out is replaced whole, the history is validated
// before it grows, the report reads only its run's files, and a failed write is an error, not an
// abort. Every test here failed on the code before its fix.
#include <gtest/gtest.h>

#include <sys/mount.h>

#include <filesystem>
#include <fstream>

#include "harness/bless.h"
#include "harness/golden_store.h"
#include "harness/one_test.h"
#include "harness/suite.h"
#include "kernel/errors.h"
#include "reports/report_writer.h"
#include "results/junit.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_hostile_output {

namespace {

// A blessed one-test suite (the furnace) in a private folder, run through the CLI.
struct Mini : FurnaceStore {
    explicit Mini(const std::string& name)
        : FurnaceStore(name, R"({"suite": "mini", "defaults": {"env": "constant:1",
                    "baseline_tolerances": {"flip.mean": {"max": 0.001}}},
                    "tests": [{"scene": "furnace", "method": "mobile"}]})") {
        EXPECT_EQ(bless_all(), kExitPass);
    }
    int run(const std::string& args, std::string& out) const {
        return run_command(
            built("iblcheck") + " run -q --suite " + suite.string() + " --goldens " + goldens.string() + " " + args, out);
    }
};

std::string bytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

} // namespace

TEST(HostileOutput, CompareNeverWritesOverAnInputNorAnExistingFileWithoutForce) {
    // `compare ref.exr test.exr --heatmap ref.exr` overwrote the reference it had just read.
    fs::path dir = temp_dir("compare_out");
    const fs::path ref = dir / "ref.exr", test = dir / "test.exr", map = dir / "map.png";
    fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "goldens/reference/furnace__constant-1.exr", ref);
    fs::copy(ref, test);
    const std::string before = bytes(ref), cmp = built("iblcheck") + " compare " + ref.string() + " " + test.string();
    std::string out;
    for (const std::string force : {"", " --force"}) {
        EXPECT_EQ(run_command(cmp + " --heatmap " + ref.string() + force, out), 2) << out;
        EXPECT_NE(out.find("--heatmap " + ref.string() + ": is also an input"), std::string::npos) << out;
        EXPECT_EQ(run_command(cmp + " --errmap " + (dir / "." / "test.exr").string() + force, out), 2) << out;
    }
    EXPECT_EQ(bytes(ref), before);
    write_file(map, "mine");
    EXPECT_EQ(run_command(cmp + " --heatmap " + map.string(), out), 2) << out;
    EXPECT_NE(out.find("--heatmap " + map.string() + ": exists; pass --force to overwrite it"), std::string::npos) << out;
    EXPECT_EQ(bytes(map), "mine");
    EXPECT_EQ(run_command(cmp + " --heatmap " + map.string() + " --force", out), 0) << out;
    EXPECT_NE(bytes(map), "mine");
    fs::remove_all(dir);
}

TEST(HostileOutput, RenderTruthRunAndReportRefuseToOverwrite) {
    Mini m("outputs");
    std::string out;
    const fs::path mine = m.dir / "mine.json";
    write_file(mine, "mine");
    // render --json (it used to be written over without --force), truth over its own --env file.
    EXPECT_EQ(run_command(built("iblcheck") + " render --scene sphere --json " + mine.string(), out), 2) << out;
    EXPECT_NE(out.find("--json " + mine.string() + ": exists"), std::string::npos) << out;
    const fs::path env = m.dir / "env.exr";
    fs::copy(m.goldens / "reference/furnace__constant-1.exr", env);
    EXPECT_EQ(run_command(
                  built("iblcheck") + " truth --scene sphere --env " + env.string() + " --out " + env.string() + " --force", out),
              2)
        << out;
    EXPECT_NE(out.find("is also an input"), std::string::npos) << out;
    // run --junit and --json; report --out into a folder that holds files.
    EXPECT_EQ(m.run("--junit " + mine.string(), out), 2) << out;
    EXPECT_EQ(m.run("--json " + mine.string(), out), 2) << out;
    EXPECT_EQ(bytes(mine), "mine");
    ASSERT_EQ(m.run("--out " + (m.dir / "run").string(), out), 0) << out;
    EXPECT_EQ(
        run_command(built("iblcheck") + " report " + (m.dir / "run/results.json").string() + " --out " + m.dir.string(), out), 2)
        << out;
    EXPECT_NE(out.find("holds files"), std::string::npos) << out;
}

// JUnit XML, `render --json` and `report`'s merged results are written beside their file and renamed
// over it (kernel/atomic_file.h), never rewritten in place: a reader that opened the old file (here a
// hard link to it) still holds it whole, and no temporary file is left. They used to be truncated and
// rewritten where they stood (a CI reading the JUnit file mid-write saw half of it; a full disk left
// half a file and lost the old one). explain --json and explore --json are written the same way.
TEST(HostileOutput, OutputsReplaceTheOldFileWholeNeverInPlace) {
    const fs::path dir = temp_dir("whole_outputs");
    auto old_file_with_reader = [&](const fs::path& f) {
        write_file(f, "old");
        const fs::path reader = fs::path(f.string() + ".reader");
        fs::create_hard_link(f, reader);
        return reader;
    };
    const fs::path junit = dir / "junit.xml";
    const fs::path junit_reader = old_file_with_reader(junit);
    write_junit(nlohmann::json{{"suite", "s"}, {"total_s", 1.0}, {"tests", nlohmann::json::array()}}, junit);
    EXPECT_EQ(bytes(junit_reader), "old");
    EXPECT_NE(bytes(junit).find("<testsuites"), std::string::npos);

    const fs::path render = dir / "render.json";
    const fs::path render_reader = old_file_with_reader(render);
    std::string out;
    ASSERT_EQ(run_command(built("iblcheck") + " render --scene sphere --env constant:1 --size 16x16 --json " + render.string() +
                              " --force",
                          out),
              0)
        << out;
    EXPECT_EQ(bytes(render_reader), "old");
    EXPECT_NE(bytes(render).find("\"timings\""), std::string::npos) << bytes(render);
    size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 4u) << "a temporary file was left in " << dir;
    fs::remove_all(dir);
}

TEST(HostileOutput, ASecondRunIntoAnOutFolderIsRefusedThenReplacedWholeWithForce) {
    // The second run wrote its files over the first's: old images stayed beside the new results.
    Mini m("out_whole");
    const fs::path out_dir = m.dir / "out";
    std::string out;
    ASSERT_EQ(m.run("--out " + out_dir.string(), out), 0) << out;
    write_file(out_dir / "images/an.earlier.test/test.png", "old"); // an earlier run's test
    EXPECT_EQ(m.run("--out " + out_dir.string(), out), 2) << out;
    EXPECT_NE(out.find("pass --force to replace it whole"), std::string::npos) << out;
    EXPECT_TRUE(fs::exists(out_dir / "images/an.earlier.test/test.png"));
    ASSERT_EQ(m.run("--force --out " + out_dir.string(), out), 0) << out;
    EXPECT_FALSE(fs::exists(out_dir / "images/an.earlier.test"));
    EXPECT_TRUE(fs::exists(out_dir / "index.html"));
    EXPECT_EQ(json::parse(bytes(out_dir / "results.json"))["tests"].size(), 1u);
    EXPECT_FALSE(fs::exists(m.dir / ".out.partial"));
    // A folder that is not a run is never replaced, not even with --force.
    write_file(m.dir / "mine/notes.txt", "mine");
    EXPECT_EQ(m.run("--force --out " + (m.dir / "mine").string(), out), 2) << out;
    EXPECT_NE(out.find("not a run folder"), std::string::npos) << out;
    EXPECT_EQ(bytes(m.dir / "mine/notes.txt"), "mine");
}

TEST(HostileOutput, AKilledRunLeavesNothingAtOutAndTheNextRunClearsItsLeftovers) {
    // A run killed with -9 left its images beside the previous run's index.html and results.json.
    Mini m("out_killed");
    const fs::path out_dir = m.dir / "out";
    write_file(m.dir / ".out.partial/images/killed.test/test.png", "half");
    write_file(m.dir / ".out.partial/index.html", "half");
    std::string out;
    ASSERT_EQ(m.run("--out " + out_dir.string(), out), 0) << out;
    EXPECT_FALSE(fs::exists(out_dir / "images/killed.test"));
    EXPECT_NE(bytes(out_dir / "index.html"), "half");
    EXPECT_FALSE(fs::exists(m.dir / ".out.partial"));
}

TEST(HostileOutput, HistoryIsValidatedBeforeAnythingIsAppended) {
    // A history truncated mid-line got the new entry glued on, and every later run exited 2.
    Mini m("history");
    const fs::path h = m.dir / "h.jsonl";
    std::string out;
    ASSERT_EQ(m.run("--history " + h.string(), out), 0) << out;
    const std::string one = bytes(h);
    write_file(h, one + one.substr(0, one.size() / 2)); // the second line cut mid-way
    const std::string cut = bytes(h);
    EXPECT_EQ(m.run("--history " + h.string(), out), 2) << out;
    EXPECT_NE(out.find(h.string() + ":2: not a JSON line"), std::string::npos) << out;
    EXPECT_EQ(bytes(h), cut);
    // A last line that lost only its newline is kept; the entry starts a line of its own.
    write_file(h, one.substr(0, one.size() - 1));
    ASSERT_EQ(m.run("--history " + h.string(), out), 0) << out;
    EXPECT_EQ(report::read_history(h).size(), 2u);
}

TEST(HostileOutput, ReportReadsOnlyFilesInsideItsRunFolder) {
    // A tampered results.json made `report` copy any readable file into out/images/_external/.
    Mini m("report_escape");
    std::string out;
    ASSERT_EQ(m.run("--out " + (m.dir / "run").string(), out), 0) << out;
    const fs::path secret = m.dir / "secret.png";
    fs::copy(m.dir / "run" / "images/mobile.furnace.constant-1.default/test.png", secret);
    fs::create_symlink(secret, m.dir / "run/link.png"); // inside by name, outside in fact
    json r = json::parse(bytes(m.dir / "run/results.json"));
    json& t = r["tests"][0];
    t["verdict"] = "fail";
    t["comparisons"][0]["images"] = {
        {"test", "../../../../../../../../etc/hostname"}, {"golden", "link.png"}, {"heatmap", secret.string()}};
    write_file(m.dir / "run/results.json", r.dump());
    ASSERT_EQ(
        run_command(built("iblcheck") + " report " + (m.dir / "run/results.json").string() + " --out " + (m.dir / "rep").string(),
                    out),
        0)
        << out;
    EXPECT_FALSE(fs::exists(m.dir / "rep/images/_external"));
    EXPECT_FALSE(fs::exists(m.dir / "rep/link.png"));
    const std::string html = bytes(m.dir / "rep/index.html");
    EXPECT_NE(html.find(secret.string() + " (outside the run&#39;s folder: not read)"), std::string::npos);
    EXPECT_NE(html.find("etc/hostname (outside the run&#39;s folder"), std::string::npos);
}

TEST(HostileOutput, AnImageThatCannotBeWrittenIsATestErrorNotAnAbort) {
    // A full disk as --out aborted the run (SIGABRT, exit 134): the render kept beside the results
    // of a test that did not pass was written outside run_test's error handling, on a worker thread.
    fs::path dir = temp_dir("write_fails");
    Suite s = load_suite("ci");
    const TestCase tc = select_tests(s, "mobile.furnace.constant:1.default", 0, 1).at(0);
    fs::create_directories(dir / "out/images" / safe_file_name(tc.name) / "test.exr"); // a folder where the file goes
    Worker w("");
    bool shader_error = false;
    json r;
    fs::create_directories(dir / "goldens/baseline"); // an empty store: the test has no golden, so does not pass
    fs::create_directories(dir / "goldens/reference");
    ASSERT_NO_THROW(r = to_json(run_test(tc, w, GoldenStore(dir / "goldens"), dir / "out", 0, 1, shader_error)));
    EXPECT_EQ(r["verdict"], "error");
    EXPECT_NE(r["message"].get<std::string>().find((dir / "out/images" / safe_file_name(tc.name) / "test.exr").string()),
              std::string::npos)
        << r["message"];
    fs::remove_all(dir);
}

TEST(HostileOutput, AFullDiskAsOutIsExitTwoNamingThePath) {
    Mini m("full_disk");
    std::string out;
    // A JUnit file on a full disk used to be reported written (the error shows only on close).
    EXPECT_EQ(m.run("--force --junit /dev/full", out), 2) << out;
    EXPECT_NE(out.find("/dev/full: cannot write JUnit XML"), std::string::npos) << out;
    const fs::path full = m.dir / "full";
    fs::create_directories(full);
    if (::mount("tmpfs", full.c_str(), "tmpfs", 0, "size=64k") != 0) GTEST_SKIP() << "cannot mount a tmpfs here (not root)";
    const int rc = m.run("--out " + (full / "out").string(), out);
    ::umount(full.c_str());
    EXPECT_EQ(rc, 2) << out;
    EXPECT_EQ(out.find("terminate called"), std::string::npos) << out;
    EXPECT_NE(out.find((full / "out").string()), std::string::npos) << out;
}
} // namespace test_hostile_output
