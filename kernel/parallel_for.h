// The one way work is spread over threads (the CPU truth's rows and table cells, FLIP's strips, the
// runner's batches of tests). Indices are handed out in increasing order, one at a time, to whichever
// worker is free; the caller's thread is one of the workers.
//
// Deterministic results are the body's part: each index writes only its own outputs (a row, a cell, a
// strip), and what is shared is summed from integers or from the per-worker states after the join.
// Then the result is the same bits for any thread count and any order (the truth's
// DeterministicAcrossThreads tests, FLIP's thread-count tests).
#pragma once
#include <atomic>
#include <functional>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace iblcheck {

// The threads `requested` asks for: itself when > 0, else the machine's (at least 1).
int resolve_threads(int requested);

// How many workers parallel_for runs for `n` indices: resolve_threads(threads), at most n (0 when n is 0).
int worker_count(int n, int threads);

namespace detail {
// Runs work(w) for w in [0, workers) on that many threads (the caller's is worker 0). The first
// exception a worker throws calls stop() and is rethrown once every worker has returned.
void run_workers(int workers, const std::function<void(int)>& work, const std::function<void()>& stop);
} // namespace detail

// Calls make_state() once per worker, on its own thread before its first index (scratch buffers, a GPU
// session), then body(i, state) for each index i in [0, n) the worker takes. Returns the states in worker
// order (of the workers that ran), for per-worker totals. A throwing body or make_state stops the
// hand-out; the first exception is rethrown here once every worker has stopped.
template <class MakeState, class Body>
auto parallel_for(int n, int threads, MakeState&& make_state, Body&& body) -> std::vector<std::invoke_result_t<MakeState&>> {
    using State = std::invoke_result_t<MakeState&>;
    const int workers = worker_count(n, threads);
    std::vector<std::optional<State>> states(static_cast<size_t>(workers));
    std::atomic<int> next{0};
    detail::run_workers(
        workers,
        [&](int w) {
            State& state = states[size_t(w)].emplace(make_state());
            for (int i; (i = next.fetch_add(1)) < n;) body(i, state);
        },
        [&] { next = n; });
    std::vector<State> out;
    out.reserve(states.size());
    for (auto& s : states)
        if (s) out.push_back(std::move(*s));
    return out;
}

// body(i) for each i in [0, n), on worker_count(n, threads) threads.
template <class Body> void parallel_for(int n, int threads, Body&& body) {
    parallel_for(
        n, threads, [] { return 0; }, [&](int i, int&) { body(i); });
}

} // namespace iblcheck
