#include "kernel/parallel_for.h"

#include <algorithm>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

namespace iblcheck {

int resolve_threads(int requested) {
    if (requested > 0) return requested;
    return std::max(1, int(std::thread::hardware_concurrency()));
}

int worker_count(int n, int threads) { return n <= 0 ? 0 : std::min(n, resolve_threads(threads)); }

namespace detail {

void run_workers(int workers, const std::function<void(int)>& work, const std::function<void()>& stop) {
    std::exception_ptr failure;
    std::mutex failure_mutex;
    auto guarded = [&](int w) {
        try {
            work(w);
        } catch (...) { // escaping a thread it would abort the process
            std::lock_guard lock(failure_mutex);
            if (!failure) failure = std::current_exception();
            stop();
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(size_t(std::max(0, workers - 1)));
    try {
        for (int w = 1; w < workers; ++w) pool.emplace_back(guarded, w);
    } catch (const std::system_error&) { // no more threads: those started (and this one) take every index
    }
    if (workers > 0) guarded(0);
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
}

} // namespace detail
} // namespace iblcheck
