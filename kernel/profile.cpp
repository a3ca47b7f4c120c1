#include "profile.h"

#include <atomic>
#include <chrono>
#include <vector>

namespace iblcheck::profile {

namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_enabled{false};

// One thread's open stages (innermost last), the moment the innermost one's clock last started,
// and the seconds each stage has had so far.
struct ThreadProfile {
    std::vector<const char*> open;
    Clock::time_point since;
    std::map<std::string, double> seconds;

    // Credits the time since `since` to the innermost open stage, and restarts its clock.
    void charge(Clock::time_point now) {
        if (!open.empty()) seconds[open.back()] += std::chrono::duration<double>(now - since).count();
        since = now;
    }
};

ThreadProfile& this_thread() {
    thread_local ThreadProfile p;
    return p;
}

} // namespace

void enable(bool on) { g_enabled.store(on, std::memory_order_relaxed); }
bool enabled() { return g_enabled.load(std::memory_order_relaxed); }

std::map<std::string, double> take() {
    ThreadProfile& p = this_thread();
    p.charge(Clock::now()); // an open stage's time so far belongs to this take
    std::map<std::string, double> out;
    out.swap(p.seconds);
    return out;
}

} // namespace iblcheck::profile

namespace iblcheck {

ProfileStage::ProfileStage(const char* name) : active_(profile::enabled()) {
    if (!active_) return;
    profile::ThreadProfile& p = profile::this_thread();
    p.charge(profile::Clock::now());
    p.open.push_back(name);
}

ProfileStage::~ProfileStage() {
    if (!active_) return;
    profile::ThreadProfile& p = profile::this_thread();
    p.charge(profile::Clock::now());
    p.open.pop_back();
}

} // namespace iblcheck
