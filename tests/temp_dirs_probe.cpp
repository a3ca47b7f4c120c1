// A test program for check_temp_dirs.cmake: one test that makes a folder with testutil::temp_dir and
// writes a file into it, and fails when IBLCHECK_PROBE_FAIL is set. The check runs it with its own
// TMPDIR and looks at what the program left behind (test_support.h: TempDirs).
#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/test_support.h"

TEST(TempDirs, Probe) {
    const std::filesystem::path d = iblcheck::testutil::temp_dir("probe");
    iblcheck::testutil::write_file(d / "left.txt", "a file the test made\n");
    ASSERT_TRUE(std::filesystem::exists(d / "left.txt"));
    if (std::getenv("IBLCHECK_PROBE_FAIL")) ADD_FAILURE() << "failing on purpose (IBLCHECK_PROBE_FAIL)";
}
