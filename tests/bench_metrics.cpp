// Speed of the metrics on the 1080p FLIP test vectors, with ratios against NVIDIA's FLIP tool
// (expected.json: reference_tool_speed, one thread, whole process). Our times exclude image
// loading, so the ratio slightly favours us; the tool's 1080p load is ~0.1 s of its total.
//   build-metrics/metrics/bench_metrics [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "metrics/flip.h"
#include "metrics/image_io.h"
#include "metrics/ssim.h"

namespace fs = std::filesystem;
using namespace iblcheck;

namespace {

const fs::path kVectors = fs::path(IBLCHECK_SHARED_DIR) / "flip-vectors";

struct Vectors {
    bool ok = false;
    cv::Mat ldr_ref, ldr_test, hdr_ref, hdr_test;
    double tool_ldr = 0, tool_hdr = 0;
};

const Vectors& vectors() {
    static Vectors v = [] {
        Vectors v;
        if (!fs::exists(kVectors / "expected.json")) return v;
        std::ifstream f(kVectors / "expected.json");
        const auto j = nlohmann::json::parse(f);
        v.tool_ldr = j["reference_tool_speed"]["ref1080_ldr"].get<double>();
        v.tool_hdr = j["reference_tool_speed"]["ramp1080_hdr_9_exposures"].get<double>();
        v.ldr_ref = read_image((kVectors / "reference.png").string()).pixels;
        v.ldr_test = read_image((kVectors / "reference_degraded.png").string()).pixels;
        v.hdr_ref = read_image((kVectors / "ramp_ref.exr").string()).pixels;
        v.hdr_test = read_image((kVectors / "ramp_test.exr").string()).pixels;
        v.ok = true;
        return v;
    }();
    return v;
}

// Counters: seconds (wall) and speedup_vs_nvidia_tool = tool seconds / our wall seconds; also
// cpu_seconds (process CPU time, all threads) and speedup_cpu = tool seconds / cpu_seconds, which
// is the fair single-thread comparison on a shared machine where wall time includes waiting.
template <class F> void timed_loop(benchmark::State& state, double tool_seconds, F&& fn) {
    double wall = 0.0, cpu = 0.0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        fn();
        cpu += double(std::clock() - c0) / CLOCKS_PER_SEC;
        wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    const double n = double(state.iterations());
    state.counters["seconds"] = wall / n;
    state.counters["cpu_seconds"] = cpu / n;
    if (tool_seconds > 0) {
        state.counters["speedup_vs_nvidia_tool"] = tool_seconds / (wall / n);
        state.counters["speedup_cpu"] = tool_seconds / (cpu / n);
    }
}

void BM_FlipLdr1080(benchmark::State& state) {
    const Vectors& v = vectors();
    if (!v.ok) return state.SkipWithError((kVectors.string() + " not found").c_str());
    FlipOptions o;
    o.threads = int(state.range(0));
    timed_loop(state, v.tool_ldr, [&] {
        benchmark::DoNotOptimize(compute_flip_ldr(v.ldr_ref, v.ldr_test, o).mean);
    });
}
BENCHMARK(BM_FlipLdr1080)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FlipHdr1080_9exp(benchmark::State& state) {
    const Vectors& v = vectors();
    if (!v.ok) return state.SkipWithError((kVectors.string() + " not found").c_str());
    FlipOptions o;
    o.threads = int(state.range(0));
    timed_loop(state, v.tool_hdr, [&] {
        const FlipResult r = compute_flip_hdr(v.hdr_ref, v.hdr_test, o);
        if (r.num_exposures != 9) state.SkipWithError("expected 9 exposures");
        benchmark::DoNotOptimize(r.mean);
    });
}
BENCHMARK(BM_FlipHdr1080_9exp)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Ssim1080(benchmark::State& state) {
    const Vectors& v = vectors();
    if (!v.ok) return state.SkipWithError((kVectors.string() + " not found").c_str());
    timed_loop(state, 0.0, [&] { benchmark::DoNotOptimize(compute_ssim(v.ldr_ref, v.ldr_test).mean); });
}
BENCHMARK(BM_Ssim1080)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
