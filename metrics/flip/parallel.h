// Deterministic row parallelism: [0, n) is split into one contiguous chunk per thread. Every
// output element is computed by exactly one thread with the same arithmetic, so results do not
// depend on the thread count; reductions are done by the caller in a fixed order afterwards.
#pragma once
#include <algorithm>
#include <thread>
#include <vector>

namespace iblcheck::flip {

inline int resolve_threads(int requested) {
    if (requested > 0) return requested;
    return std::max(1, int(std::thread::hardware_concurrency()));
}

template <class F> void parallel_rows(int n, int threads, F&& fn) {
    threads = std::max(1, std::min(threads, n / 8)); // tiny images: not worth a thread
    if (threads <= 1) {
        fn(0, n);
        return;
    }
    const int chunk = (n + threads - 1) / threads;
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) {
        const int b = t * chunk, e = std::min(n, b + chunk);
        if (b < e) workers.emplace_back([&fn, b, e] { fn(b, e); });
    }
    fn(0, std::min(n, chunk));
    for (auto& w : workers) w.join();
}

} // namespace iblcheck::flip
