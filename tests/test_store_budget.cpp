// The stores' size budget (kernel/store_budget.h, issue 33): least recently used entries go first, a
// command's own entries stay, nothing but an entry is touched, a hit counts as a use, and the budget
// comes from IBLCHECK_CACHE_MAX_MB or is refused by name. The binary end to end:
// tests/check_store_budget.cmake.
#include "kernel/store_budget.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "kernel/errors.h"
#include "kernel/store_entry.h"
#include "tests/test_support.h"

using namespace iblcheck;
using namespace iblcheck::testutil;
namespace fs = std::filesystem;
using std::chrono::hours;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_store_budget {

namespace {

const fs::file_time_type kNow = fs::file_time_type::clock::now();

// An entry of `bytes` bytes last used `age` ago.
fs::path plant(const fs::path& dir, const std::string& name, size_t bytes, fs::file_time_type::duration age) {
    fs::create_directories(dir);
    const fs::path p = dir / name;
    std::ofstream(p, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(p, kNow - age);
    return p;
}

// A test's own folder, removed after it.
struct Scratch {
    explicit Scratch(const std::string& name) : dir(temp_dir(name)) {}
    ~Scratch() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    fs::path dir;
};

struct BudgetEnv {
    explicit BudgetEnv(const char* value) {
        if (const char* old = std::getenv("IBLCHECK_CACHE_MAX_MB")) saved = old, had = true;
        if (value)
            setenv("IBLCHECK_CACHE_MAX_MB", value, 1);
        else
            unsetenv("IBLCHECK_CACHE_MAX_MB");
    }
    ~BudgetEnv() {
        if (had)
            setenv("IBLCHECK_CACHE_MAX_MB", saved.c_str(), 1);
        else
            unsetenv("IBLCHECK_CACHE_MAX_MB");
    }
    std::string saved;
    bool had = false;
};

} // namespace

TEST(StoreBudget, LeastRecentlyUsedGoFirstUntilTheStoresFit) {
    const Scratch scratch("store_budget_lru");
    const fs::path& tmp = scratch.dir;
    const fs::path a = tmp / "precompute", b = tmp / "metrics";
    // Ages across two folders, so the order is the entries' and not a folder's.
    const fs::path e4 = plant(a, "04.ibl", 100, hours(4)), e3 = plant(b, "03.metrics", 100, hours(3)),
                   e2 = plant(a, "02.ibl", 100, hours(2)), e1 = plant(b, "01.metrics", 100, hours(1)),
                   e0 = plant(a, "00.ibl", 100, hours(0) + std::chrono::minutes(1));
    const std::vector<StoreFolder> folders{{a, ".ibl"}, {b, ".metrics"}};
    EXPECT_EQ(store_usage(folders).bytes, 500u);
    const PruneOutcome o = prune_stores(folders, 250, kNow);
    EXPECT_EQ(o.before.entries, 5u);
    EXPECT_EQ(o.before.bytes, 500u);
    EXPECT_EQ(o.removed, 3u);
    EXPECT_EQ(o.removed_bytes, 300u);
    EXPECT_EQ(o.after.entries, 2u);
    EXPECT_EQ(o.after.bytes, 200u);
    EXPECT_FALSE(fs::exists(e4));
    EXPECT_FALSE(fs::exists(e3));
    EXPECT_FALSE(fs::exists(e2));
    EXPECT_TRUE(fs::exists(e1));
    EXPECT_TRUE(fs::exists(e0));
    // Within the budget: nothing goes.
    const PruneOutcome again = prune_stores(folders, 250, kNow);
    EXPECT_EQ(again.removed, 0u);
    EXPECT_EQ(again.after.bytes, 200u);
}

TEST(StoreBudget, ACommandsOwnEntriesStayOverTheBudget) {
    const Scratch scratch("store_budget_own");
    const fs::path& tmp = scratch.dir;
    const fs::path d = tmp / "cost";
    const fs::path old = plant(d, "0a.cost", 100, hours(48));
    const fs::path own1 = plant(d, "0b.cost", 100, std::chrono::seconds(0)),
                   own2 = plant(d, "0c.cost", 100, std::chrono::seconds(0));
    // The command started an hour ago: its two entries (200 bytes) are over a 50-byte budget alone.
    const PruneOutcome o = prune_stores({{d, ".cost"}}, 50, kNow - hours(1));
    EXPECT_EQ(o.removed, 1u);
    EXPECT_FALSE(fs::exists(old));
    EXPECT_TRUE(fs::exists(own1));
    EXPECT_TRUE(fs::exists(own2));
    EXPECT_EQ(o.after.bytes, 200u);
}

TEST(StoreBudget, OnlyEntriesAreCountedOrRemoved) {
    EXPECT_TRUE(is_store_entry_name("00bf8a5b9726b998.ibl", ".ibl"));
    EXPECT_TRUE(is_store_entry_name("007a32bbeca63710.metrics", ".metrics"));
    EXPECT_FALSE(is_store_entry_name("00bf8a5b9726b998.ibl.tmp123-456.ibl", ".ibl")); // a writer's temporary file
    EXPECT_FALSE(is_store_entry_name("00BF8A5B.ibl", ".ibl"));
    EXPECT_FALSE(is_store_entry_name(".ibl", ".ibl"));
    EXPECT_FALSE(is_store_entry_name("00bf8a5b.cost", ".ibl"));
    EXPECT_FALSE(is_store_entry_name("notes.ibl", ".ibl"));

    const Scratch scratch("store_budget_only");
    const fs::path& tmp = scratch.dir;
    const fs::path d = tmp / "precompute";
    const fs::path entry = plant(d, "0d.ibl", 100, hours(10));
    const fs::path tmpfile = plant(d, "0d.ibl.tmp7-8.ibl", 1000, hours(20)), note = plant(d, "README", 1000, hours(20));
    fs::create_directories(d / "0e.ibl");                                   // a folder with an entry's name
    const fs::path other = plant(tmp / "cost", "0f.cost", 1000, hours(30)); // not a listed folder
    const PruneOutcome o = prune_stores({{d, ".ibl"}, {tmp / "missing", ".metrics"}, {fs::path(), ".cost"}}, 0, kNow);
    EXPECT_EQ(o.before.entries, 1u);
    EXPECT_EQ(o.before.bytes, 100u);
    EXPECT_EQ(o.removed, 1u);
    EXPECT_FALSE(fs::exists(entry));
    EXPECT_TRUE(fs::exists(tmpfile));
    EXPECT_TRUE(fs::exists(note));
    EXPECT_TRUE(fs::is_directory(d / "0e.ibl"));
    EXPECT_TRUE(fs::exists(other));
}

// A hit is a use: of two entries written long ago, the one read since stays when one must go.
TEST(StoreBudget, AHitMakesAnEntryRecentlyUsed) {
    const Scratch scratch("store_budget_hit");
    const fs::path& tmp = scratch.dir;
    const fs::path d = tmp / "metrics";
    const fs::path read = d / "01.metrics", unread = d / "02.metrics";
    write_store_entry(read, "HEAD-one");
    write_store_entry(unread, "HEAD-two");
    EXPECT_TRUE(store_entries_written());
    fs::last_write_time(read, kNow - hours(5));
    fs::last_write_time(unread, kNow - hours(4)); // the younger of the two until the read
    ASSERT_EQ(read_store_entry(read, "HEAD-"), std::optional<std::string>("one"));
    EXPECT_GT(fs::last_write_time(read), kNow - std::chrono::seconds(1));
    // A miss (another store's head) is no use.
    EXPECT_EQ(read_store_entry(unread, "OTHER"), std::nullopt);
    EXPECT_LT(fs::last_write_time(unread), kNow - hours(3));
    const PruneOutcome o = prune_stores({{d, ".metrics"}}, 8, kNow - hours(1));
    EXPECT_EQ(o.removed, 1u);
    EXPECT_TRUE(fs::exists(read));
    EXPECT_FALSE(fs::exists(unread));
}

// An entry reads back byte for byte after its head, whatever its size and bytes (zeros included); a file
// shorter than the head, another head or no file is a miss.
TEST(StoreBudget, AnEntryReadsBackWholeAfterItsHead) {
    const Scratch scratch("store_entry_read");
    const fs::path d = scratch.dir / "precompute";
    std::string big(3u << 20, '\0');
    for (size_t i = 0; i < big.size(); ++i) big[i] = char((i * 2654435761u) >> 13);
    write_store_entry(d / "big.ibl", "MAGIC" + big);
    EXPECT_EQ(read_store_entry(d / "big.ibl", "MAGIC"), std::optional<std::string>(big));
    write_store_entry(d / "empty.ibl", "MAGIC");
    EXPECT_EQ(read_store_entry(d / "empty.ibl", "MAGIC"), std::optional<std::string>(""));
    write_store_entry(d / "short.ibl", "MAG");
    EXPECT_EQ(read_store_entry(d / "short.ibl", "MAGIC"), std::nullopt);
    EXPECT_EQ(read_store_entry(d / "big.ibl", "MAGIK"), std::nullopt);
    EXPECT_EQ(read_store_entry(d / "none.ibl", "MAGIC"), std::nullopt);
}

TEST(StoreBudget, BudgetComesFromTheEnvironmentAndABadValueIsNamed) {
    {
        BudgetEnv e(nullptr);
        EXPECT_EQ(store_budget_bytes(), kDefaultStoreBudgetMiB << 20);
    }
    {
        BudgetEnv e("");
        EXPECT_EQ(store_budget_bytes(), kDefaultStoreBudgetMiB << 20);
    }
    {
        BudgetEnv e("512");
        EXPECT_EQ(store_budget_bytes(), std::uintmax_t(512) << 20);
    }
    for (const char* bad : {"0", "-1", "1.5", "abc", "2G", " 5", "99999999999999999999"}) {
        BudgetEnv e(bad);
        try {
            store_budget_bytes();
            ADD_FAILURE() << "IBLCHECK_CACHE_MAX_MB=" << bad << " was taken";
        } catch (const UsageError& err) {
            EXPECT_NE(std::string(err.what()).find(std::string("IBLCHECK_CACHE_MAX_MB='") + bad + "'"), std::string::npos)
                << err.what();
        }
    }
}
} // namespace test_store_budget
