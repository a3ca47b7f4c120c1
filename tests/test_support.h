// Helpers every test file shares: private temporary folders, running the CLI, reading and writing
// small text files, the message of an InputError.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

#include "kernel/errors.h"

namespace iblcheck::testutil {

// The folders temp_dir made, removed when the test program exits, unless a test failed: then they
// stay for a look, and the program says where. (Without this, every run of the tests left ~20 of them
// behind: 1650 in /tmp after two days of runs.) Only the process that made them removes them, not a
// forked child.
class TempDirs {
  public:
    void add(const std::filesystem::path& p) {
        for (const auto& q : dirs_)
            if (q == p) return;
        dirs_.push_back(p);
    }
    ~TempDirs() {
        if (::getpid() != owner_) return;
        const ::testing::UnitTest* u = ::testing::UnitTest::GetInstance();
        for (const auto& p : dirs_) {
            std::error_code ec;
            if (u->Failed())
                std::fprintf(stderr, "a test failed: its files stay in %s\n", p.c_str());
            else
                std::filesystem::remove_all(p, ec);
        }
    }
    static TempDirs& made() {
        static TempDirs d;
        return d;
    }

  private:
    pid_t owner_ = ::getpid();
    std::vector<std::filesystem::path> dirs_;
};

// An empty folder under the system temp folder, unique to this process: <tmp>/iblcheck_<name>_<pid>.
// It goes when the program exits (TempDirs).
inline std::filesystem::path temp_dir(const std::string& name) {
    std::filesystem::path p = std::filesystem::temp_directory_path() / ("iblcheck_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    TempDirs::made().add(p);
    return p;
}

#ifdef IBLCHECK_BINARY_DIR
// A file of the build folder: built("iblcheck") is the CLI the tests run.
inline std::string built(const std::string& name) { return (std::filesystem::path(IBLCHECK_BINARY_DIR) / name).string(); }
#endif

// Runs a shell command; returns its exit status (-1 if it did not exit) and its output (stdout,
// and stderr too unless merge_stderr is false, e.g. to parse JSON from stdout).
inline int run_command(const std::string& cmd, std::string& out, bool merge_stderr = true) {
    FILE* pipe = popen((merge_stderr ? cmd + " 2>&1" : cmd).c_str(), "r");
    if (!pipe) return -1;
    std::array<char, 4096> buf;
    out.clear();
    while (fgets(buf.data(), int(buf.size()), pipe)) out += buf.data();
    int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string read_text(const std::filesystem::path& p) {
    std::ifstream f(p);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p) << text;
}

// The message of the InputError `f` throws; "(no error)" when it throws none.
template <class F> std::string input_error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace iblcheck::testutil
