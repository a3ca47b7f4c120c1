// The runner's work between its workers: batches of tests that share a precompute (renderer.h:
// precompute_share_key), grouped by the radiance chain they derive from (radiance_chain_share_key).
// A free worker takes the next batch of the chain it is on, so its GPU session computes that chain
// once; else the first chain that no worker is on (chains come largest first); else a batch of the
// chain with the most tests left, which another worker is on: its session computes that chain again,
// and two busy workers beat one idle one. Handing out whole chains instead left the TSan slice (23
// tests, one chain) on one worker: 72.7 s against 50.6 s (issue 33).
#pragma once
#include <cstddef>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

namespace iblcheck {

using Batch = std::vector<size_t>;       // test indices that share one precompute
using ChainBatches = std::vector<Batch>; // the batches of one radiance chain

// How many tests batches hold (a chain's, or what is left of it).
template <class Batches> size_t tests_in(const Batches& batches) {
    size_t n = 0;
    for (const Batch& b : batches) n += b.size();
    return n;
}

class BatchQueue {
  public:
    explicit BatchQueue(const std::vector<ChainBatches>& chains);
    // The next batch for worker `w`, or nothing when every batch is taken. Thread-safe.
    std::optional<Batch> next(int w);
    // No batch is handed out after this (a worker failed: the others stop after their batch).
    void close();

  private:
    std::mutex mutex_;
    std::vector<std::deque<Batch>> chains_;
    std::vector<int> workers_on_;    // per chain
    std::map<int, size_t> chain_of_; // worker → the chain it is on
};

} // namespace iblcheck
