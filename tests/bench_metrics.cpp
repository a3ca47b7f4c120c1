// Speed of the metrics, measured in one run (issue 20):
//   - the FLIP kernel in-process (image loading excluded) on 1920x1080 LDR and HDR (9 exposures)
//     pairs, for each kernel variant this CPU runs (scalar reference, sse2, avx2: flip/kernels.h),
//     at 1 and 2 threads;
//   - SSIM at 1080p;
//   - whole-process `iblcheck compare` of a 512x512 LDR pair (start-up, PNG reading, all metrics).
// Then it prints ratios between those measurements: vectorised vs scalar, 2 threads vs 1. Times are
// process CPU seconds (all threads) and wall seconds; on a shared machine CPU time is the figure to
// compare, wall time includes waiting for a core.
// The pairs are generated here (deterministic), so the benchmark runs in a fresh clone. When the
// shared FLIP vectors (../shared/flip-vectors) are present, their 1080p pairs are measured too, and
// NVIDIA's tool's timings stored there are printed as context: they were taken on another run and
// are never divided into a ratio here.
//   cmake --build build --target bench_metrics && build/metrics/bench_metrics [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "image_io/image_io.h"
#include "metrics/flip.h"
#include "metrics/flip/kernels.h"
#include "metrics/ssim.h"

extern char** environ;

namespace fs = std::filesystem;
using namespace iblcheck;

namespace {

const fs::path kVectors = fs::path(IBLCHECK_SHARED_DIR) / "flip-vectors";
// The 1080p HDR vector's exposure range (ramp_ref.exr: 9 exposures); the synthetic HDR pair is
// scored over the same exposures so both cases do the same work.
constexpr float kHdrStart = -4.88279f, kHdrStop = 4.037529f;

// Smooth gradients, hard edges and noise: every FLIP stage has work, and LDR values are k/255.
cv::Mat synthetic_pair_image(int w, int h, unsigned seed, bool hdr, bool degraded) {
    cv::Mat m(h, w, CV_32FC3);
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, degraded ? 0.04f : 0.0f);
    for (int y = 0; y < h; ++y) {
        float* p = m.ptr<float>(y);
        for (int x = 0; x < w; ++x, p += 3) {
            const float u = float(x) / float(w), v = float(y) / float(h);
            const bool check = ((x / 37) + (y / 29)) % 2 == 0;
            float c[3] = {0.5f + 0.4f * std::sin(9.0f * u + 3.0f * v), check ? 0.8f : 0.2f,
                          0.5f + 0.45f * std::cos(13.0f * v - 5.0f * u)};
            for (int i = 0; i < 3; ++i) {
                float val = c[i] + noise(rng);
                if (hdr) {
                    p[i] = std::max(0.0f, val) * std::exp2(8.0f * u - 4.0f); // ~8 stops across the image
                } else {
                    val = std::min(std::max(val, 0.0f), 1.0f);
                    p[i] = std::round(val * 255.0f) / 255.0f;
                }
            }
        }
    }
    return m;
}

struct Pair {
    cv::Mat ref, test;
};

const Pair& synthetic(bool hdr) {
    static const Pair ldr{synthetic_pair_image(1920, 1080, 1, false, false), synthetic_pair_image(1920, 1080, 2, false, true)};
    static const Pair hdrp{synthetic_pair_image(1920, 1080, 3, true, false), synthetic_pair_image(1920, 1080, 4, true, true)};
    return hdr ? hdrp : ldr;
}

struct Vectors {
    bool ok = false;
    Pair ldr, hdr;
    nlohmann::json tool_speed; // NVIDIA's tool, stored in expected.json (context only)
};

const Vectors& vectors() {
    static const Vectors v = [] {
        Vectors v;
        if (!fs::exists(kVectors / "expected.json")) return v;
        std::ifstream f(kVectors / "expected.json");
        v.tool_speed = nlohmann::json::parse(f).value("reference_tool_speed", nlohmann::json::object());
        v.ldr = {read_image((kVectors / "reference.png").string()).pixels,
                 read_image((kVectors / "reference_degraded.png").string()).pixels};
        v.hdr = {read_image((kVectors / "ramp_ref.exr").string()).pixels,
                 read_image((kVectors / "ramp_test.exr").string()).pixels};
        v.ok = true;
        return v;
    }();
    return v;
}

void run_flip(benchmark::State& state, const Pair& p, bool hdr, const flip::Kernels& k, int threads) {
    FlipOptions o;
    o.threads = threads;
    o.kernels = &k;
    if (hdr) {
        o.start_exposure = kHdrStart;
        o.stop_exposure = kHdrStop;
        o.num_exposures = 9;
    }
    for (auto _ : state) {
        const FlipResult r = hdr ? compute_flip_hdr(p.ref, p.test, o) : compute_flip_ldr(p.ref, p.test, o);
        benchmark::DoNotOptimize(r.mean);
    }
}

void register_flip(const std::string& input, bool hdr, const std::function<const Pair*()>& pair) {
    for (const flip::Kernels* k : flip::available_kernels())
        for (int threads : {1, 2}) {
            if (threads == 2 && k == &flip::scalar_kernels()) continue; // the reference: 1 thread is enough
            const std::string name =
                fmt::format("flip/{}/{}/{}/threads:{}", input, hdr ? "hdr1080_9exp" : "ldr1080", k->name, threads);
            benchmark::RegisterBenchmark(name.c_str(),
                                         [=](benchmark::State& st) {
                                             const Pair* p = pair();
                                             if (!p) return st.SkipWithError("input not available");
                                             run_flip(st, *p, hdr, *k, threads);
                                         })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime()
                ->MeasureProcessCPUTime()
                ->MinTime(hdr ? 2.0 : 1.0);
        }
}

// Whole process: `iblcheck compare ref.png test.png` (default metrics), CPU of the child from wait4.
void BM_CompareProcess512(benchmark::State& state) {
    const fs::path cli = IBLCHECK_CLI_PATH;
    if (!fs::exists(cli)) return state.SkipWithError((cli.string() + " not built").c_str());
    const fs::path dir = fs::temp_directory_path() / ("iblcheck_bench_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string a = (dir / "ref.png").string(), b = (dir / "test.png").string();
    write_png(a, synthetic_pair_image(512, 512, 5, false, false));
    write_png(b, synthetic_pair_image(512, 512, 6, false, true));
    double child_cpu = 0;
    const std::string metric = state.range(0) ? "all" : "flip";
    for (auto _ : state) {
        std::vector<std::string> args = {cli.string(), "compare", a, b, "--metric", metric, "--threads", "1"};
        std::vector<char*> argv;
        for (auto& s : args) argv.push_back(s.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t fa;
        posix_spawn_file_actions_init(&fa);
        posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
        pid_t pid;
        if (posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) {
            posix_spawn_file_actions_destroy(&fa);
            return state.SkipWithError("posix_spawn failed");
        }
        posix_spawn_file_actions_destroy(&fa);
        int status = 0;
        rusage ru{};
        wait4(pid, &status, 0, &ru);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return state.SkipWithError("iblcheck compare failed");
        child_cpu += double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    }
    state.counters["child_cpu_s"] = benchmark::Counter(child_cpu / double(state.iterations()));
    fs::remove_all(dir);
}
BENCHMARK(BM_CompareProcess512)->ArgName("all_metrics")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Ssim1080(benchmark::State& state) {
    const Pair& p = synthetic(false);
    for (auto _ : state) benchmark::DoNotOptimize(compute_ssim(p.ref, p.test).mean);
}
BENCHMARK(BM_Ssim1080)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// Collects every run (and still prints the usual table), for the ratios at the end.
class RatioReporter : public benchmark::ConsoleReporter {
  public:
    struct Times {
        double cpu_s = 0, wall_s = 0;
    };
    std::map<std::string, Times> runs;
    // Colours only on a terminal (the table is often redirected to a file).
    RatioReporter() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_Defaults : OO_Tabular) {}
    void ReportRuns(const std::vector<Run>& reports) override {
        ConsoleReporter::ReportRuns(reports);
        for (const Run& r : reports) {
            if (r.error_occurred || r.iterations == 0) continue;
            // Repetitions: keep the fastest (least disturbed by other load).
            const double n = double(r.iterations);
            Times t{r.cpu_accumulated_time / n, r.real_accumulated_time / n};
            if (r.counters.count("child_cpu_s")) t.cpu_s = r.counters.at("child_cpu_s").value;
            // The registered name (and arguments), without the min_time/process_time/real_time suffixes.
            const std::string key = r.run_name.function_name + (r.run_name.args.empty() ? "" : "/" + r.run_name.args);
            auto it = runs.find(key);
            if (it == runs.end() || t.cpu_s < it->second.cpu_s) runs[key] = t;
        }
    }
    const Times* find(const std::string& name) const {
        auto it = runs.find(name);
        return it == runs.end() ? nullptr : &it->second;
    }
};

std::string seconds(const RatioReporter::Times* t) { return t ? fmt::format("{:.3f} s", t->cpu_s) : "n/a"; }

void print_ratios(const RatioReporter& rep) {
    std::printf("\nRatios measured in this run (CPU time for kernels, wall time for threads):\n");
    const std::string best = flip::default_kernels().name;
    for (const std::string input : {"synthetic", "vectors"})
        for (const std::string pair : {"ldr1080", "hdr1080_9exp"}) {
            auto name = [&](const std::string& k, int t) { return fmt::format("flip/{}/{}/{}/threads:{}", input, pair, k, t); };
            const auto* scalar = rep.find(name("scalar", 1));
            if (!scalar) continue;
            for (const flip::Kernels* k : flip::available_kernels()) {
                if (k == &flip::scalar_kernels()) continue;
                if (const auto* v = rep.find(name(k->name, 1)))
                    std::printf("  %-9s %-13s %-6s vs scalar, 1 thread:  %5.2fx  (%.3f s vs %.3f s CPU)\n", input.c_str(),
                                pair.c_str(), k->name, scalar->cpu_s / v->cpu_s, v->cpu_s, scalar->cpu_s);
            }
            const auto* one = rep.find(name(best, 1));
            const auto* two = rep.find(name(best, 2));
            if (one && two)
                std::printf("  %-9s %-13s %-6s 2 threads vs 1:       %5.2fx  (%.3f s vs %.3f s wall)\n", input.c_str(),
                            pair.c_str(), best.c_str(), one->wall_s / two->wall_s, two->wall_s, one->wall_s);
        }
    const Vectors& v = vectors();
    if (!v.ok) {
        std::printf("\nShared FLIP vectors: skipped (%s not found); the synthetic pairs above have the same "
                    "sizes and exposure count.\n",
                    kVectors.string().c_str());
        return;
    }
    std::printf("\nContext, not measured here (NVIDIA FLIP tool v1.6, whole process, 1 thread, stored in %s):\n",
                (kVectors / "expected.json").string().c_str());
    for (auto& [key, value] : v.tool_speed.items())
        if (value.is_number()) std::printf("  %-28s %.3f s\n", key.c_str(), value.get<double>());
    std::printf("  (this run, %s, 1 thread, CPU: LDR 1080p %s, HDR 1080p 9 exposures %s; whole-process compare "
                "512x512 LDR --metric flip %s)\n",
                best.c_str(), seconds(rep.find("flip/vectors/ldr1080/" + best + "/threads:1")).c_str(),
                seconds(rep.find("flip/vectors/hdr1080_9exp/" + best + "/threads:1")).c_str(),
                seconds(rep.find("BM_CompareProcess512/all_metrics:0")).c_str());
}

} // namespace

int main(int argc, char** argv) {
    register_flip("synthetic", false, [] { return &synthetic(false); });
    register_flip("synthetic", true, [] { return &synthetic(true); });
    if (fs::exists(kVectors / "expected.json")) {
        register_flip("vectors", false, []() -> const Pair* { return vectors().ok ? &vectors().ldr : nullptr; });
        register_flip("vectors", true, []() -> const Pair* { return vectors().ok ? &vectors().hdr : nullptr; });
    } else {
        std::printf("Shared FLIP vectors: %s not found; their benchmarks are skipped, the synthetic ones run.\n",
                    kVectors.string().c_str());
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    RatioReporter rep;
    benchmark::RunSpecifiedBenchmarks(&rep);
    print_ratios(rep);
    benchmark::Shutdown();
    return 0;
}
