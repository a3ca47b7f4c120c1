// kernel/parallel_for.h, the one thread pool (issue 31): every index exactly once for any thread count,
// one state per worker with exact merged totals, and a throwing body rethrown in the caller (a body that
// threw in the CPU truth's or the Monte Carlo integrator's own pools aborted the process).
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "kernel/parallel_for.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_parallel_for {

TEST(ParallelFor, EveryIndexExactlyOnceForAnyThreadCount) {
    for (int n : {0, 1, 7, 100})
        for (int threads : {1, 2, 3, 8, 0}) {
            std::vector<std::atomic<int>> seen(static_cast<size_t>(n));
            parallel_for(n, threads, [&](int i) { ++seen[size_t(i)]; });
            for (int i = 0; i < n; ++i) EXPECT_EQ(seen[size_t(i)], 1) << "n " << n << ", threads " << threads << ", index " << i;
        }
}

TEST(ParallelFor, WorkersAreTheThreadsAtMostOneAnIndex) {
    EXPECT_EQ(worker_count(0, 4), 0);
    EXPECT_EQ(worker_count(3, 8), 3);
    EXPECT_EQ(worker_count(100, 2), 2);
    EXPECT_EQ(worker_count(100, 0), resolve_threads(0));
    EXPECT_GE(resolve_threads(0), 1);
    EXPECT_EQ(resolve_threads(5), 5);
}

// A state per worker, made on its thread; the per-worker counts add up to every index, and the states
// come back one per worker.
TEST(ParallelFor, StatesPerWorkerMergeToExactTotals) {
    struct Count {
        long indices = 0, sum = 0;
    };
    for (int threads : {1, 2, 5}) {
        const std::vector<Count> counts = parallel_for(
            1000, threads, [] { return Count{}; },
            [](int i, Count& c) {
                ++c.indices;
                c.sum += i;
            });
        ASSERT_EQ(int(counts.size()), worker_count(1000, threads));
        long indices = 0, sum = 0;
        for (const Count& c : counts) indices += c.indices, sum += c.sum;
        EXPECT_EQ(indices, 1000);
        EXPECT_EQ(sum, 999L * 1000 / 2);
    }
}

// Per-index outputs are the same bits whatever the thread count.
TEST(ParallelFor, PerIndexOutputsDoNotDependOnTheThreadCount) {
    auto run = [](int threads) {
        std::vector<double> out(257);
        parallel_for(257, threads, [&](int i) {
            double v = 0;
            for (int k = 1; k <= i + 1; ++k) v += 1.0 / (double(k) * (i + 1));
            out[size_t(i)] = v;
        });
        return out;
    };
    const std::vector<double> one = run(1);
    for (int threads : {2, 4, 7}) EXPECT_EQ(run(threads), one) << threads << " threads";
}

TEST(ParallelFor, AThrowingBodyIsRethrownInTheCaller) {
    for (int threads : {1, 4})
        EXPECT_THROW(parallel_for(1000, threads,
                                  [](int i) {
                                      if (i == 5) throw std::runtime_error("index 5");
                                  }),
                     std::runtime_error)
            << threads << " threads";
    // The hand-out stops at the failure: on one thread no index after it runs.
    int ran_after = 0;
    EXPECT_THROW(parallel_for(100, 1,
                              [&](int i) {
                                  if (i == 5) throw std::runtime_error("index 5");
                                  ran_after += i > 5;
                              }),
                 std::runtime_error);
    EXPECT_EQ(ran_after, 0);
    // A worker that cannot make its state (the runner's: no GPU device) fails the call too.
    EXPECT_THROW(parallel_for(
                     8, 3, []() -> int { throw std::runtime_error("no device"); }, [](int, int&) {}),
                 std::runtime_error);
}
} // namespace test_parallel_for
