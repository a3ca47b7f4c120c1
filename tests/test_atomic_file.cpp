// kernel/atomic_file.h, the one atomic file writer (issue 31), and the writers that use it: the results
// JSON, the golden store. A failed write names the file and leaves no temporary file behind (the results
// JSON's and the report page's copies left theirs when the rename failed); the golden store, the one
// writer of goldens, keeps an EXR whose pixels are bit-identical (the truth's rule, now bless's too).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "harness/golden_store.h"
#include "harness/run_files.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_atomic_file {

namespace {

class AtomicFile : public ::testing::Test {
  protected:
    void SetUp() override { dir_ = testutil::temp_dir("atomic_file"); }
    void TearDown() override { fs::remove_all(dir_); }
    // The names in the folder (a leftover temporary file shows here).
    std::set<std::string> names() const {
        std::set<std::string> out;
        for (const auto& e : fs::directory_iterator(dir_)) out.insert(e.path().filename().string());
        return out;
    }
    fs::path dir_;
};

ino_t inode(const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 ? st.st_ino : 0;
}

} // namespace

TEST_F(AtomicFile, WritesTheBytesAsTheyAreAndReplacesAWholeFile) {
    const std::string bytes("a\0b\r\nc", 6);
    write_file_atomically(dir_ / "f.bin", bytes);
    EXPECT_EQ(testutil::read_text(dir_ / "f.bin"), bytes);
    write_file_atomically(dir_ / "f.bin", "short");
    EXPECT_EQ(testutil::read_text(dir_ / "f.bin"), "short");
    EXPECT_EQ(names(), std::set<std::string>{"f.bin"});
}

// A target that is a FIFO (or a device: /dev/stdout, /dev/full) is written into and stays what it is:
// renamed over, the node itself was replaced by a regular file (as root, `--junit /dev/full` turned
// /dev/full into one). A reader on the FIFO gets the bytes; nothing is left beside it.
TEST_F(AtomicFile, AFifoTargetIsWrittenIntoNotReplaced) {
    const fs::path fifo = dir_ / "out.xml";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    // Opened read-write, a FIFO never blocks: this end is its reader, and a write of a few bytes fits.
    const int fd = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK);
    ASSERT_GE(fd, 0);
    write_file_atomically(fifo, "<testsuites/>\n", "JUnit XML");
    char buf[64];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    ::close(fd);
    EXPECT_EQ(std::string(buf, size_t(std::max<ssize_t>(n, 0))), "<testsuites/>\n");
    EXPECT_TRUE(fs::is_fifo(fifo));
    EXPECT_EQ(names(), std::set<std::string>{"out.xml"});
}

// The target is a folder that is not empty: the rename fails. The error names the file and what it is;
// no temporary file is left.
TEST_F(AtomicFile, AFailedRenameNamesTheFileAndLeavesNoTemporaryFile) {
    fs::create_directories(dir_ / "results.json" / "inside");
    const std::string msg = testutil::input_error_of([&] {
        write_json_atomically(dir_ / "results.json", nlohmann::json{{"a", 1}});
    });
    EXPECT_NE(msg.find((dir_ / "results.json").string() + ": cannot write results JSON: "), std::string::npos) << msg;
    EXPECT_EQ(names(), std::set<std::string>{"results.json"});
    EXPECT_FALSE(try_write_file_atomically(dir_ / "results.json", "x"));
    EXPECT_EQ(names(), std::set<std::string>{"results.json"});
}

TEST_F(AtomicFile, AMissingFolderNamesTheFile) {
    const fs::path f = dir_ / "no_such_folder" / "index.html";
    const std::string msg = testutil::input_error_of([&] { write_file_atomically(f, "<html>", "the report"); });
    EXPECT_NE(msg.find(f.string() + ": cannot write the report: "), std::string::npos) << msg;
}

// A writer that fails half-way (the EXR writer on a full disk): its error comes through, the old file is
// untouched, and its temporary file is gone.
TEST_F(AtomicFile, AFailingWriterLeavesTheOldFileAndNoTemporaryFile) {
    write_file_atomically(dir_ / "g.exr", "old");
    EXPECT_THROW(write_file_atomically(dir_ / "g.exr",
                                       [](const fs::path& tmp) {
                                           testutil::write_file(tmp, "half");
                                           throw InputError(tmp.string() + ": disk full");
                                       }),
                 InputError);
    EXPECT_EQ(testutil::read_text(dir_ / "g.exr"), "old");
    EXPECT_EQ(names(), std::set<std::string>{"g.exr"});
}

// The golden store writes every golden (bless and `iblcheck truth`): pixels bit-identical to the golden's
// keep its EXR (the same file), the sidecar is rewritten; other pixels replace it.
TEST_F(AtomicFile, TheGoldenStoreKeepsAnEXRWithTheSamePixels) {
    const fs::path exr = dir_ / "reference" / "g.exr";
    cv::Mat image(4, 3, CV_32FC3, cv::Scalar(0.25f, 0.5f, 1.0f));
    GoldenStore::write_golden(exr, image, {{"n", 1}});
    const ino_t first = inode(exr);
    GoldenStore::write_golden(exr, image.clone(), {{"n", 2}});
    EXPECT_EQ(inode(exr), first) << "bit-identical pixels: the EXR is kept";
    EXPECT_EQ(nlohmann::json::parse(testutil::read_text(dir_ / "reference" / "g.json"))["n"], 2);
    image.at<cv::Vec3f>(1, 1)[0] = 0.75f;
    GoldenStore::write_golden(exr, image, {{"n", 3}});
    EXPECT_NE(inode(exr), first);
    EXPECT_EQ(read_image(exr.string()).pixels.at<cv::Vec3f>(1, 1)[0], 0.75f);
    EXPECT_EQ(nlohmann::json::parse(testutil::read_text(dir_ / "reference" / "g.json"))["n"], 3);
    std::set<std::string> in_reference;
    for (const auto& e : fs::directory_iterator(dir_ / "reference")) in_reference.insert(e.path().filename().string());
    EXPECT_EQ(in_reference, (std::set<std::string>{"g.exr", "g.json"}));
}

// A golden named without a folder (`iblcheck truth --out g.exr`) lands in the current folder (the store's
// writer refused it, "cannot create the golden folder", once the truth wrote through it).
TEST_F(AtomicFile, AGoldenWithoutAFolderIsWrittenInTheCurrentOne) {
    const fs::path was = fs::current_path();
    fs::current_path(dir_);
    EXPECT_NO_THROW(GoldenStore::write_golden("g.exr", cv::Mat(2, 2, CV_32FC3, cv::Scalar(1, 1, 1)), {{"n", 1}}));
    fs::current_path(was);
    EXPECT_EQ(names(), (std::set<std::string>{"g.exr", "g.json"}));
}
} // namespace test_atomic_file
