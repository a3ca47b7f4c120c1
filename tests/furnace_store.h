// A private golden root for the tests that bless and run a one-test suite: the suite file, and the
// furnace's reference golden copied in (the truth a furnace test under constant:1 judges against).
// Shared by the gate's and the hostile-input tests, which each add their own ways to run it.
#pragma once
#include <filesystem>
#include <string>

#include "harness/bless.h"
#include "harness/golden_store.h"
#include "tests/test_support.h"

namespace iblcheck::testutil {

inline const std::string kFurnaceTest = "mobile.furnace.constant:1.default";

struct FurnaceStore {
    std::filesystem::path dir, suite, goldens;

    FurnaceStore(const std::string& name, const std::string& suite_text)
        : dir(temp_dir(name)), suite(dir / "mini.json"), goldens(dir / "goldens") {
        write_file(suite, suite_text);
        std::filesystem::create_directories(goldens / "reference");
        for (const char* ext : {".exr", ".json"})
            std::filesystem::copy(std::filesystem::path(IBLCHECK_SOURCE_DIR) /
                                      (std::string("goldens/reference/furnace__constant-1") + ext),
                                  goldens / "reference");
    }
    FurnaceStore(const FurnaceStore&) = delete;
    FurnaceStore& operator=(const FurnaceStore&) = delete;
    ~FurnaceStore() { std::filesystem::remove_all(dir); }

    BlessOptions bless_options() const {
        BlessOptions b;
        b.suite = suite.string();
        b.goldens = goldens;
        return b;
    }
    int bless_all() const { return bless(bless_options()); }
    std::filesystem::path baseline(const std::string& test = kFurnaceTest) const {
        return GoldenStore(goldens).baseline_path(test);
    }
    std::filesystem::path sidecar(const std::string& test = kFurnaceTest) const {
        return std::filesystem::path(baseline(test)).replace_extension(".json");
    }
};

} // namespace iblcheck::testutil
