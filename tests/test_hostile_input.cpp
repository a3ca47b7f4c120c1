// Hostile input (issue 30): image headers that claim more pixels than the file holds, files that
// are not regular files (FIFOs, folders), and malformed suite files. Each is refused with exit 2 /
// InputError naming the file and the problem, before anything large is allocated and without
// blocking on a FIFO.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <regex>
#include <string>

#include "harness/golden_store.h"
#include "harness/suite.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "renderers/environments/environment.h"
#include "reports/report_writer.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_hostile_input {

namespace {

class HostileInput : public ::testing::Test {
  protected:
    static void SetUpTestSuite() { dir_ = testutil::temp_dir("hostile_input"); }
    static void TearDownTestSuite() { fs::remove_all(dir_); }
    static std::string path(const std::string& name) { return (dir_ / name).string(); }
    static fs::path dir_;
};
fs::path HostileInput::dir_;

// What `fn` throws, in a child process: a reader that opens a FIFO blocks until a writer comes,
// so the old code would hang the test; the child is killed by SIGALRM after 30 s ("hung").
std::string error_in_child(const std::function<void()>& fn) {
    int fds[2];
    if (pipe(fds) != 0) return "pipe failed";
    const pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        alarm(30);
        std::string msg = "no exception";
        try {
            fn();
        } catch (const InputError& e) {
            msg = e.what();
        } catch (const std::exception& e) {
            msg = std::string("not an InputError: ") + e.what();
        }
        (void)!write(fds[1], msg.data(), msg.size());
        _exit(0);
    }
    close(fds[1]);
    std::string out;
    char buf[512];
    for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, size_t(n));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFSIGNALED(status) ? "hung (killed by signal " + std::to_string(WTERMSIG(status)) + ")" : out;
}

std::string error_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("not an InputError: ") + e.what();
    }
    return "no exception";
}

// Rewrites an OpenEXR file's dataWindow and displayWindow to 0,0 - w-1,h-1 (the header's
// attributes: name\0 type\0 size value).
void claim_exr_size(const std::string& file, int w, int h) {
    std::string b = testutil::read_text(file);
    for (size_t i = 8; b[i] != 0;) {
        const size_t name_end = b.find('\0', i), type_end = b.find('\0', name_end + 1);
        const std::string name = b.substr(i, name_end - i);
        int32_t size = 0;
        std::memcpy(&size, &b[type_end + 1], 4);
        const size_t value = type_end + 5;
        if (name == "dataWindow" || name == "displayWindow") {
            const int32_t box[4] = {0, 0, w - 1, h - 1};
            std::memcpy(&b[value], box, sizeof box);
        }
        i = value + size_t(size);
    }
    std::ofstream(file, std::ios::binary) << b;
}

// Rewrites a PNG's IHDR width and height (and its CRC).
void claim_png_size(const std::string& file, uint32_t w, uint32_t h) {
    std::string b = testutil::read_text(file);
    auto put_be = [&](size_t at, uint32_t v) {
        for (int k = 0; k < 4; ++k) b[at + size_t(k)] = char((v >> (24 - 8 * k)) & 0xff);
    };
    put_be(16, w); // signature (8), IHDR length (4), "IHDR" (4)
    put_be(20, h);
    put_be(29, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(&b[12]), 17))); // over "IHDR" + 13 bytes
    std::ofstream(file, std::ios::binary) << b;
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

} // namespace

// A 64x1024 EXR of zeros (a few KB) whose header says 8000x2000: 192 MB of floats cannot come out
// of it at deflate's 1032:1. The old reader allocated them, then failed reading.
TEST_F(HostileInput, ExrClaimBeyondWhatTheFileHoldsIsRefused) {
    write_exr(path("claim.exr"), cv::Mat::zeros(1024, 64, CV_32FC3));
    claim_exr_size(path("claim.exr"), 8000, 2000);
    const std::string e = error_of([] { read_image(path("claim.exr")); });
    EXPECT_TRUE(starts_with(e, path("claim.exr") + ": header claims 8000x2000 pixels (192000000 bytes of pixel data)")) << e;
    EXPECT_NE(e.find("(1032:1)"), std::string::npos) << e;
}

TEST_F(HostileInput, PngClaimsAreRefusedBeforeAllocating) {
    write_png(path("claim.png"), cv::Mat::zeros(64, 64, CV_32FC3));
    claim_png_size(path("claim.png"), 2000, 2000);
    std::string e = error_of([] { read_image(path("claim.png")); });
    EXPECT_TRUE(starts_with(e, path("claim.png") + ": header claims 2000x2000 pixels (12000000 bytes of pixel data)")) << e;
    // libpng's largest size: the old reader threw std::bad_alloc ("internal:", no file named).
    claim_png_size(path("claim.png"), 1000000, 1000000);
    e = error_of([] { read_image(path("claim.png")); });
    EXPECT_EQ(e, path("claim.png") + ": header claims 1000000x1000000 pixels, more than iblcheck reads (at most "
                                     "134217728 pixels, e.g. 16384x8192)");
}

// Radiance HDR goes through OpenImageIO: the claim is held to the stated maximum before the
// harness allocates the buffer (the old reader allocated 1.6 GB, then failed on the first scanline).
TEST_F(HostileInput, OiioClaimBeyondTheMaximumIsRefused) {
    testutil::write_file(path("claim.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8193 +X 16384\n" + std::string(64, '\0'));
    const std::string e = error_of([] { read_image(path("claim.hdr")); });
    EXPECT_EQ(e, path("claim.hdr") + ": header claims 16384x8193 pixels, more than iblcheck reads (at most 134217728 "
                                     "pixels, e.g. 16384x8192)");
}

// The bound is the compression's largest ratio, not a guess: files of zeros, which compress
// about as well as anything, are still read.
TEST_F(HostileInput, HighlyCompressedFilesAreStillRead) {
    write_exr(path("zeros.exr"), cv::Mat::zeros(1024, 2048, CV_32FC3));
    write_png(path("zeros.png"), cv::Mat::zeros(1024, 2048, CV_32FC3));
    for (const char* name : {"zeros.exr", "zeros.png"}) {
        const LoadedImage li = read_image(path(name));
        EXPECT_EQ(li.pixels.cols, 2048) << name;
        EXPECT_EQ(li.pixels.rows, 1024) << name;
        EXPECT_EQ(cv::countNonZero(li.pixels.reshape(1)), 0) << name;
    }
}

// A FIFO in every place the tool reads a file the user names. The old readers opened it and
// blocked forever (nothing writes to it); each is now refused before it is opened.
TEST_F(HostileInput, FifosAreRefusedByEveryReader) {
    const std::string fifo = path("fifo.exr"), fifo_json = path("fifo.json");
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    ASSERT_EQ(mkfifo(fifo_json.c_str(), 0600), 0);
    const std::string is_fifo = ": is a FIFO (named pipe), not a regular file";
    EXPECT_EQ(error_in_child([&] { read_image(fifo); }), fifo + is_fifo);
    EXPECT_EQ(error_in_child([&] { load_environment(fifo); }), "environment file '" + fifo + "'" + is_fifo);
    EXPECT_EQ(error_in_child([&] { load_suite(fifo_json); }), fifo_json + is_fifo);
    EXPECT_EQ(error_in_child([&] { read_results(fifo_json); }), fifo_json + is_fifo);
    EXPECT_EQ(error_in_child([&] { read_history(fifo_json); }), fifo_json + is_fifo);
    // A golden whose sidecar is a FIFO.
    const fs::path goldens = dir_ / "goldens";
    const fs::path golden = GoldenStore(goldens).baseline_path("t");
    fs::create_directories(golden.parent_path());
    write_exr(golden.string(), cv::Mat::zeros(4, 4, CV_32FC3));
    const std::string side = fs::path(golden).replace_extension(".json").string();
    ASSERT_EQ(mkfifo(side.c_str(), 0600), 0);
    EXPECT_EQ(error_in_child([&] { GoldenStore(goldens).baselines("t"); }), side + is_fifo);
}

// The CLI's own readers: `compare --pairs FILE` (`-` is still stdin) and `truth --compare OLD`
// (checked before the render, which takes minutes).
TEST_F(HostileInput, CliRefusesFifos) {
    const std::string fifo = path("cli_fifo");
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    const std::string cli = "timeout 30 " + testutil::built("iblcheck") + " ";
    std::string out;
    EXPECT_EQ(testutil::run_command(cli + "compare --pairs " + fifo, out), 2);
    EXPECT_EQ(out, "error: " + fifo + ": is a FIFO (named pipe), not a regular file\n");
    EXPECT_EQ(testutil::run_command(cli + "truth --scene sphere --env studio --out " + path("t.exr") + " --compare " + fifo, out),
              2);
    EXPECT_EQ(out, "error: " + fifo + ": is a FIFO (named pipe), not a regular file\n");
    EXPECT_FALSE(fs::exists(path("t.exr")));
    // '-' still reads the list from stdin.
    EXPECT_EQ(testutil::run_command("echo '' | " + cli + "compare --pairs -", out), 0) << out;
}

TEST_F(HostileInput, AFolderIsNotASuite) {
    fs::create_directories(path("folder.json"));
    EXPECT_EQ(error_of([] { load_suite(path("folder.json")); }), path("folder.json") + ": is a folder, not a regular file");
}

// Suite files that reached "internal:" (a JSON library exception naming no file).
TEST_F(HostileInput, MalformedSuitesNameFilePlaceAndProblem) {
    const std::string test = R"({"scene": "sphere", "method": "mobile")";
    auto suite_error = [&](const std::string& name, const std::string& body) {
        testutil::write_file(path(name), body);
        return error_of([&] { load_suite(path(name)); });
    };
    EXPECT_EQ(suite_error("n.json", R"({"suite": "x", "defaults": {"max_cost_growth": 1e400}, "tests": [)" + test + "}]}"),
              path("n.json") + ": defaults.max_cost_growth: not valid JSON: [json.exception.out_of_range.406] number "
                               "overflow parsing '1e400'");
    EXPECT_EQ(suite_error("m.json", R"({"suite": "x", "tests": [)" + test + R"(}, {"options": {"ao": [1, -1e999]}}]})"),
              path("m.json") + ": tests[1].options.ao[1]: not valid JSON: [json.exception.out_of_range.406] number "
                               "overflow parsing '-1e999'");
    EXPECT_EQ(suite_error("t.json", R"({"suite": "x", "tests": [)" + test + R"(, "tags": "abc"}]})"),
              path("t.json") + ": tests[0].tags: must be an array of strings, not string");
    // Counts that a double such as 1e300 does not fit (an int conversion out of range).
    EXPECT_EQ(suite_error("j.json", R"({"suite": "x", "defaults": {"jobs": 1e300}, "tests": [)" + test + "}]}"),
              path("j.json") + ": defaults.jobs: must be an integer in 1..1024, not 1e+300");
    EXPECT_EQ(
        suite_error("r.json", R"({"suite": "x", "tests": [)" + test + R"(, "temporal": {"frames": 4, "reference_ssaa": -3}}]})"),
        path("r.json") + ": tests[0].temporal.reference_ssaa: must be an integer in 1..64, not -3");
    // An option value above 2^63 is shown as written, not wrapped to -1.
    EXPECT_EQ(
        suite_error("u.json", R"({"suite": "x", "tests": [)" + test + R"(, "options": {"roughness": 18446744073709551615}}]})"),
        path("u.json") + ": tests[0]: option 'roughness': 18446744073709551615 is outside [0, 1]");
}

// A shader that writes NaN into alpha, the coverage the texture-fetch cost is computed from. The
// old code rendered it with exit 0 ("texture samples/px nan") and `run` blamed the cost:
// "cost: cost.texture_fetches_per_pixel -nan (approved 2.596) is NaN". Now the shader, the channel
// and the first pixel are named, and it is a regression (exit 1, verdict fail), on both paths.
TEST_F(HostileInput, NanCoverageIsBlamedOnTheShaderNotTheCost) {
    const fs::path shaders = dir_ / "nan_alpha" / "shaders";
    fs::create_directories(shaders.parent_path());
    fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "renderers" / "shaders", shaders, fs::copy_options::recursive);
    const std::pair<const char*, const char*> edits[] = {
        {"shade_spheres.comp", "return vec4(shade_surface(s, n, v, roughness), 1.0);"},
        {"shade_spheres.frag", "color = vec4(shade_surface(s, n, v, roughness), 1.0);"}};
    for (const auto& [file, from] : edits) {
        std::string text = testutil::read_text(shaders / file);
        const size_t at = text.find(from);
        ASSERT_NE(at, std::string::npos) << file;
        const std::string to = std::string(from).replace(std::string(from).find("1.0)"), 4, "0.0 / (roughness - roughness))");
        testutil::write_file(shaders / file, text.replace(at, std::string(from).size(), to));
    }
    const std::string cli = "IBLCHECK_CACHE_DIR=" + (dir_ / "nan_alpha").string() + " IBLCHECK_SHADER_DIR=" + shaders.string() +
                            " " + IBLCHECK_BINARY_DIR + "/iblcheck ";
    const std::string named_re =
        R"(alpha \(coverage\) channel: [1-9][0-9]* non-finite value\(s\) \(NaN/Inf\), first at x=\d+, y=\d+)";
    const std::regex named(named_re);
    std::string out;
    EXPECT_EQ(testutil::run_command(cli + "render --scene sphere --method mobile", out), 1) << out;
    EXPECT_TRUE(std::regex_search(out, std::regex("shade_spheres.comp: " + named_re))) << out;
    EXPECT_EQ(testutil::run_command(cli + "render --scene sphere --method mobile --set shading=fragment", out), 1) << out;
    EXPECT_TRUE(std::regex_search(out, std::regex("shade_spheres.frag: " + named_re))) << out;
    const std::string json_file = (dir_ / "nan_alpha" / "r.json").string();
    EXPECT_EQ(testutil::run_command(cli + "run --suite ci -q --filter mobile.sphere.studio.default --json " + json_file, out), 1)
        << out;
    const nlohmann::json t = nlohmann::json::parse(testutil::read_text(json_file))["tests"][0];
    EXPECT_EQ(t["verdict"], "fail");
    const std::string message = t["message"];
    EXPECT_TRUE(std::regex_search(message, named)) << message;
    EXPECT_EQ(message.find("cost"), std::string::npos) << message;
}
} // namespace test_hostile_input
