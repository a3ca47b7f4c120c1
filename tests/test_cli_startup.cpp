// What the iblcheck process loads (issue 20): commands that read no image load no OpenImageIO,
// commands that render nothing load no Vulkan driver (lavapipe and its LLVM), and a PNG/EXR compare
// loads neither. Checked through the dynamic linker's own log (LD_DEBUG=files), not by timing.
// Also `--version` and `compare --pairs` through the built binary.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "image_io/image_io.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_cli_startup {

namespace {

const std::string kCli = testutil::built("iblcheck");

// The shared objects the dynamic linker opened for `iblcheck ARGS` (LD_DEBUG=files: "file=NAME [0];
// needed by ..." or "... dynamically loaded by ...").
std::string loaded_libraries(const std::string& args, int& rc) {
    std::string out;
    rc = testutil::run_command("LD_DEBUG=files " + kCli + " " + args + " 2>&1 >/dev/null", out, false);
    std::string libs;
    for (size_t at = out.find("file="); at != std::string::npos; at = out.find("file=", at + 5)) {
        const size_t end = out.find(" [", at);
        if (end != std::string::npos && out.find('\n', at) > end) libs += out.substr(at + 5, end - at - 5) + "\n";
    }
    return libs;
}

bool has(const std::string& libs, const std::string& name) { return libs.find(name) != std::string::npos; }

class CliStartup : public ::testing::Test {
  protected:
    static void SetUpTestSuite() { dir_ = testutil::temp_dir("cli_startup"); }
    static void TearDownTestSuite() { fs::remove_all(dir_); }
    static std::string path(const std::string& name) { return (dir_ / name).string(); }
    static fs::path dir_;
};
fs::path CliStartup::dir_;

cv::Mat gradient(int w, int h, float shift) {
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) m.ptr<float>(y)[3 * x + c] = std::min(1.0f, float(x + y + 5 * c) / float(w + h) + shift);
    return m;
}

TEST_F(CliStartup, CommandsWithoutImagesLoadNeitherOpenImageIONorVulkanDriver) {
    for (const std::string args : {"--help", "--version", "list", "compare --help", "run --help"}) {
        int rc = -1;
        const std::string libs = loaded_libraries(args, rc);
        EXPECT_EQ(rc, 0) << args;
        ASSERT_TRUE(has(libs, "libc.so")) << "LD_DEBUG gave no library list for " << args << ":\n" << libs;
        EXPECT_FALSE(has(libs, "libOpenImageIO")) << args << " loaded OpenImageIO:\n" << libs;
        EXPECT_FALSE(has(libs, "libvulkan_lvp")) << args << " loaded lavapipe";
        EXPECT_FALSE(has(libs, "libLLVM")) << args << " loaded LLVM";
    }
}

TEST_F(CliStartup, PngAndExrCompareLoadsNeitherOpenImageIONorVulkanDriver) {
    write_png(path("a.png"), gradient(32, 24, 0.0f));
    write_png(path("b.png"), gradient(32, 24, 0.05f));
    write_exr(path("a.exr"), gradient(32, 24, 0.0f) * 4.0);
    write_exr(path("b.exr"), gradient(32, 24, 0.1f) * 4.0);
    for (const std::string& args : {path("a.png") + " " + path("b.png"), path("a.exr") + " " + path("b.exr")}) {
        int rc = -1;
        const std::string libs = loaded_libraries("compare " + args, rc);
        EXPECT_EQ(rc, 0) << args;
        EXPECT_FALSE(has(libs, "libOpenImageIO")) << "compare " << args << " loaded OpenImageIO:\n" << libs;
        EXPECT_FALSE(has(libs, "libvulkan_lvp")) << args;
    }
}

TEST_F(CliStartup, OtherFormatsLoadOpenImageIOOnFirstRead) {
    // The plugin is what makes other formats work: a float TIFF pair is compared through it.
    write_exr(path("c.tif"), gradient(16, 16, 0.0f));
    write_exr(path("d.tif"), gradient(16, 16, 0.2f));
    int rc = -1;
    const std::string libs = loaded_libraries("compare " + path("c.tif") + " " + path("d.tif"), rc);
    EXPECT_EQ(rc, 0);
    EXPECT_TRUE(has(libs, "libiblcheck_oiio.so")) << libs;
    EXPECT_TRUE(has(libs, "libOpenImageIO")) << libs;
}

TEST_F(CliStartup, VersionNamesCommitCompilerAndBuildType) {
    std::string out;
    ASSERT_EQ(testutil::run_command(kCli + " --version", out), 0) << out;
    // iblcheck 0.1 (commit 0123456789ab[-dirty] | unknown, GNU 12.2.0, RelWithDebInfo)
    ASSERT_EQ(out.rfind("iblcheck ", 0), 0u) << out;
    const size_t open = out.find(" (commit "), close = out.rfind(")\n");
    ASSERT_NE(open, std::string::npos) << out;
    ASSERT_EQ(close, out.size() - 2) << out;
    std::istringstream fields(out.substr(open + 9, close - open - 9)); // "<commit>, <compiler> <version>, <type>"
    std::string commit, compiler, version, type;
    std::getline(fields, commit, ',');
    fields >> compiler >> version >> type;
    const std::string hex = commit.substr(0, commit.find('-'));
    EXPECT_TRUE(commit == "unknown" || (hex.size() >= 7 && hex.find_first_not_of("0123456789abcdef") == std::string::npos &&
                                        (hex == commit || commit == hex + "-dirty")))
        << commit;
    EXPECT_EQ(compiler, std::string(IBLCHECK_EXPECTED_COMPILER)) << out;
    EXPECT_EQ(version.back(), ',') << out; // "12.2.0,"
    EXPECT_EQ(type, std::string(IBLCHECK_EXPECTED_BUILD_TYPE)) << out;
}

TEST_F(CliStartup, ComparePairsFromStdinAndFromAFile) {
    write_png(path("p1.png"), gradient(24, 24, 0.0f));
    write_png(path("p2.png"), gradient(24, 24, 0.1f));
    const std::string list = path("p1.png") + " " + path("p2.png") + "\n# a comment\n\n" + path("p2.png") + "\t" +
                             path("p1.png") + "\n" + path("p1.png") + " " + path("missing.png") + "\n";
    testutil::write_file(path("pairs.txt"), list);
    for (const std::string& source : {"--pairs " + path("pairs.txt"), "--pairs - < " + path("pairs.txt")}) {
        std::string out;
        const int rc = testutil::run_command(kCli + " compare --metric flip " + source + " 2>/dev/null", out, false);
        EXPECT_EQ(rc, 2) << "a pair could not be compared: exit 2\n" << out;
        std::vector<nlohmann::json> lines;
        std::istringstream ss(out);
        for (std::string l; std::getline(ss, l);) lines.push_back(nlohmann::json::parse(l));
        ASSERT_EQ(lines.size(), 3u) << out;
        EXPECT_EQ(lines[0]["reference"], path("p1.png"));
        EXPECT_EQ(lines[0]["line"], 1);
        EXPECT_GT(lines[0]["flip"]["mean"].get<double>(), 0.0);
        EXPECT_EQ(lines[1]["reference"], path("p2.png")); // tab-separated line
        EXPECT_EQ(lines[1]["line"], 4);
        EXPECT_EQ(lines[2]["error"], path("missing.png") + ": file not found");
        EXPECT_EQ(lines[2]["line"], 5);
        EXPECT_FALSE(lines[2].contains("flip"));
    }
}

} // namespace
} // namespace test_cli_startup
