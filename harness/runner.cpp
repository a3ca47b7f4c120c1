#include "runner.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fmt/core.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "bless.h"
#include "harness/common/errors.h"
#include "image_compare.h"
#include "junit.h"
#include "metrics/display_transform.h"
#include "metrics/image_io.h"
#include "provenance.h"
#include "reports/report_writer.h"
#include "stability.h"
#include "temporal_check.h"
#include "verdict.h"
#include "worker.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// The image files of one test, under <out>/images/<test>/; results name them relative to <out>.
struct Artefacts {
    fs::path dir;
    std::string rel;  // "images/<test>/"
    explicit operator bool() const { return !dir.empty(); }
    std::string png(const std::string& name, const cv::Mat& linear) const {
        fs::create_directories(dir);
        write_png((dir / name).string(), display_transform(linear));
        return rel + name;
    }
    std::string heatmap(const std::string& name, const cv::Mat& errmap) const {
        fs::create_directories(dir);
        write_png((dir / name).string(), magma_heatmap(errmap));
        return rel + name;
    }
};

// What the test is, before anything is rendered.
json test_header(const TestCase& tc) {
    return {{"name", tc.name}, {"suite", tc.suite}, {"scene", tc.spec.scene}, {"method", tc.spec.method},
            {"env", tc.spec.env}, {"options", tc.spec.options.values()}, {"variant", tc.variant}, {"tags", tc.tags},
            {"bless_command", bless_command(tc)}, {"comparisons", json::array()}, {"accuracy", nullptr},
            {"driver_mismatch", nullptr}};
}

void record_render(json& r, const RenderResult& rr) {
    r["width"] = rr.image.cols;
    r["height"] = rr.image.rows;
    double pre = 0, frame = 0;
    json t = json::array();
    for (auto& p : rr.timings) {
        t.push_back({{"pass", p.name}, {"ms", p.ms}, {"gpu", p.gpu}, {"precompute", p.precompute}});
        (p.precompute ? pre : frame) += p.ms;
    }
    r["timings"] = t;
    r["precompute_ms"] = pre;
    r["frame_ms"] = frame;
    r["texture_fetches_per_pixel"] = rr.texture_fetches_per_pixel;
    r["cost"] = render_cost(rr);
    r["provenance"] = rr.provenance;
}

// Where the error concentrates, for a person: "worst 16x16 block at (160,16) on metal r=0.3 ...".
std::string worst_block(const TestSpec& spec, const FlipResult& flip, int width, int height) {
    std::string sphere = sphere_at(spec, width, height, std::min(flip.block_x + 8, width - 1),
                                   std::min(flip.block_y + 8, height - 1));
    return fmt::format("worst 16x16 block at ({},{}){} with mean FLIP {:.4g}", flip.block_x, flip.block_y,
                       sphere.empty() ? "" : " on " + sphere, flip.block_max);
}

struct BaselineOutcome {
    Comparison comparison;
    bool missing = false;
    Golden golden;       // the baseline judged against (empty image when missing)
};

// Any of the test's approved baselines may pass it; the report shows the one that did, or the
// closest one.
BaselineOutcome judge_against_baselines(const TestCase& tc, const cv::Mat& image, const GoldenStore& store,
                                        const Artefacts& art, int flip_threads) {
    BaselineOutcome out;
    std::vector<Golden> goldens = store.baselines(tc.name);
    if (goldens.empty()) {
        out.missing = true;
        out.comparison.kind = "baseline";
        out.comparison.verdict = Verdict::missing_golden;
        out.comparison.message = "no baseline golden at " + store.baseline_path(tc.name).string() +
                                 "; create it with: " + bless_command(tc);
        return out;
    }
    std::vector<Comparison> candidates;
    for (const Golden& g : goldens) {
        Comparison c;
        if (g.image.size() != image.size()) {
            c = judge_size("baseline", image.cols, image.rows, g.image.cols, g.image.rows);
        } else {
            FlipResult flip;
            c = judge_baseline(compare_images(g.image, image, flip_threads, &flip), tc.baseline_tolerances);
            if (c.verdict == Verdict::fail) c.message += "; " + worst_block(tc.spec, flip, image.cols, image.rows);
            if (art) {
                std::string tag = g.label.empty() ? "baseline" : "baseline@" + safe_file_name(g.label);
                c.images = {{"test", art.rel + "test.png"}, {"golden", art.png(tag + ".png", g.image)},
                            {"heatmap", art.heatmap(tag + "_flip.png", flip.errmap)}};
            }
        }
        c.golden = store.relative(g.image_path);
        c.label = g.label;
        candidates.push_back(std::move(c));
    }
    size_t i = choose_baseline(candidates);
    out.comparison = std::move(candidates[i]);
    out.golden = goldens[i];
    return out;
}

// The render's cost per pixel against the cost recorded with the baseline. A baseline without a
// recorded cost cannot gate it: that is a failure to re-bless, not a silent pass.
std::vector<Check> judge_costs(const TestCase& tc, const RenderResult& rr, const Golden& golden) {
    std::vector<Check> out;
    const json now = render_cost(rr), approved = golden.provenance.value("cost", json::object());
    for (auto& [key, value] : now.items()) {
        if (!approved.contains(key) || !approved[key].is_number()) {
            Check c{"cost." + key, value.get<double>(), {}, {}, {}, Verdict::fail,
                    "cost." + key + ": the baseline records no approved cost; re-bless it (" + bless_command(tc) + ")"};
            out.push_back(c);
            continue;
        }
        out.push_back(judge_cost("cost." + key, value.get<double>(), approved[key].get<double>(), tc.max_cost_growth));
    }
    return out;
}

// Accuracy against the reference golden, judged by the band around the baseline's approved accuracy.
Comparison judge_against_truth(const TestCase& tc, const cv::Mat& image, const Golden& ref, const GoldenStore& store,
                               const json& approved_accuracy, const Artefacts& art, int flip_threads, json& r) {
    if (ref.image.size() != image.size()) {
        Comparison c = judge_size("reference", image.cols, image.rows, ref.image.cols, ref.image.rows);
        c.golden = store.relative(ref.image_path);
        return c;
    }
    FlipResult flip;
    json metrics = compare_images(ref.image, image, flip_threads, &flip);
    Comparison c = judge_reference(metrics, approved_accuracy, tc.reference_band);
    c.golden = store.relative(ref.image_path);
    if (c.verdict == Verdict::fail) c.message += "; " + worst_block(tc.spec, flip, image.cols, image.rows);
    r["accuracy"] = {{"flip_mean", flip.mean}, {"ssim", metrics["ssim"]["mean"]}, {"golden", c.golden},
                     {"noise_floor", ref.provenance.value("noise_floor", json())}};
    if (json ps = per_sphere_errors(tc.spec, flip.errmap); !ps.is_null()) r["per_sphere"] = ps;
    if (art)
        c.images = {{"test", art.rel + "test.png"}, {"golden", art.png("reference.png", ref.image)},
                    {"heatmap", art.heatmap("reference_flip.png", flip.errmap)}};
    return c;
}

// One test: render, compare, decide. Never throws: every outcome becomes a verdict.
json run_test(const TestCase& tc, Worker& w, const GoldenStore& store, const fs::path& out_dir, int flip_threads,
              bool& shader_error) {
    json r = test_header(tc);
    Artefacts art;
    if (!out_dir.empty()) art = {out_dir / "images" / safe_file_name(tc.name), "images/" + safe_file_name(tc.name) + "/"};
    std::vector<Verdict> verdicts;
    std::vector<std::string> problems;
    auto add = [&](Verdict v, const std::string& message) {
        verdicts.push_back(v);
        if (!message.empty()) problems.push_back(message);
    };
    const auto t0 = std::chrono::steady_clock::now();
    cv::Mat image;
    try {
        RenderResult rr = w.renderer.render(tc.spec);
        image = rr.image;
        record_render(r, rr);
        if (NonFinite nf = find_non_finite(rr.image); nf.count) throw NonFiniteRender("render: " + nf.describe());
        if (art) r["image"] = art.png("test.png", rr.image);

        BaselineOutcome base;
        if (tc.baseline) {
            base = judge_against_baselines(tc, rr.image, store, art, flip_threads);
            r["comparisons"].push_back(to_json(base.comparison));
            add(base.comparison.verdict, base.missing ? base.comparison.message : base.comparison.message.empty() ? "" : "baseline: " + base.comparison.message);
            if (!base.missing) {
                Comparison cost;
                cost.kind = "cost";
                cost.golden = base.comparison.golden;
                cost.checks = judge_costs(tc, rr, base.golden);
                for (const Check& k : cost.checks) {
                    cost.message += k.message.empty() ? "" : (cost.message.empty() ? "" : "; ") + k.message;
                    cost.verdict = overall_verdict({cost.verdict, k.status});
                }
                r["comparisons"].push_back(to_json(cost));
                add(cost.verdict, cost.message);
                std::string diff = platform_difference(base.golden.provenance, rr.provenance, this_cpu_class());
                if (!diff.empty()) r["driver_mismatch"] = diff;
            }
        }
        cv::Mat reference;
        if (tc.reference)
            if (auto ref = store.reference(tc.spec)) {
                reference = ref->image;
                json approved = base.golden.provenance.value("accuracy", json());
                Comparison c = judge_against_truth(tc, rr.image, *ref, store, approved, art, flip_threads, r);
                r["comparisons"].push_back(to_json(c));
                add(c.verdict, c.message.empty() ? "" : "accuracy: " + c.message);
            }
        if (tc.temporal.frames > 0) {
            TemporalOutcome t = run_temporal(tc, w, store, art.dir, art.rel, flip_threads);
            r["temporal"] = t.json;
            for (const Check& k : t.checks) add(k.status, k.message.empty() ? "" : "temporal: " + k.message);
        }
        if (tc.stability.enabled) {
            StabilityOutcome s = run_stability(tc, w, rr.image, reference,
                                               base.golden.provenance.value("accuracy", json()), flip_threads);
            r["stability"] = s.json;
            bool fails = !s.deterministic || (s.flaky && tc.stability.fail_on_flaky);
            add(fails ? Verdict::fail : Verdict::pass, s.problem);
        }
    } catch (const ShaderCompileError& e) {
        shader_error = true;
        add(Verdict::error, std::string("shader compile failed: ") + e.what());
    } catch (const NonFiniteRender& e) {
        add(Verdict::fail, e.what());
    } catch (const std::exception& e) {
        add(Verdict::error, e.what());
    }
    Verdict v = overall_verdict(verdicts);
    r["verdict"] = verdict_name(v);
    std::string msg;
    for (auto& p : problems) msg += (msg.empty() ? "" : "; ") + p;
    if (r["driver_mismatch"].is_string() && v != Verdict::pass)
        msg += (msg.empty() ? "" : "; ") + r["driver_mismatch"].get<std::string>();
    r["message"] = msg;
    if (v != Verdict::pass && art && !image.empty()) {
        fs::create_directories(art.dir);
        write_exr((art.dir / "test.exr").string(), image);
    }
    r["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

// Holds <out>/.iblcheck.lock for the run: a second run into the same folder is refused instead of
// interleaving its files with this one's.
class OutDirLock {
  public:
    explicit OutDirLock(const fs::path& dir) {
        if (dir.empty()) return;
        std::error_code ec;
        fs::create_directories(dir, ec);
        if (ec) throw InputError(dir.string() + ": cannot create the output folder: " + ec.message());
        fs::path lock = dir / ".iblcheck.lock";
        fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd_ < 0) throw InputError(lock.string() + ": cannot open: " + std::strerror(errno));
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            char buf[32] = {};
            ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
            ::close(fd_);
            throw UsageError(fmt::format("{}: another iblcheck run{} is writing into this folder; wait for it or use "
                                         "another --out", dir.string(), n > 0 ? fmt::format(" (pid {})", buf) : ""));
        }
        std::string pid = std::to_string(::getpid());
        if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
        }
    }
    ~OutDirLock() {
        if (fd_ >= 0) ::close(fd_);
    }
    OutDirLock(const OutDirLock&) = delete;
    OutDirLock& operator=(const OutDirLock&) = delete;

  private:
    int fd_ = -1;
};

void write_json_atomically(const fs::path& file, const json& j) {
    fs::path tmp = file;
    tmp += ".tmp" + std::to_string(::getpid());
    {
        std::ofstream f(tmp);
        f << j.dump(1) << "\n";
        if (!f) throw InputError(file.string() + ": cannot write results JSON");
    }
    fs::rename(tmp, file);
}

void print_test_line(const json& r, int n, size_t total, bool interactive) {
    std::string acc = r["accuracy"].is_object() ? fmt::format("  vs truth {:.4f}", r["accuracy"]["flip_mean"].get<double>()) : "";
    const std::string v = r["verdict"].get<std::string>();
    fmt::print("{}[{:>3}/{}] {:<15} {}{}  ({:.1f} s)\n", interactive ? "\r" : "", n, total, v,
               r["name"].get<std::string>(), acc, r["wall_s"].get<double>());
    if (v != "pass" && !r["message"].get<std::string>().empty()) fmt::print("          {}\n", r["message"].get<std::string>());
    if (is_regression(parse_verdict(v))) fmt::print("          approve this result: {}\n", r["bless_command"].get<std::string>());
    std::fflush(stdout);
}

} // namespace

int RunSummary::exit_code() const {
    if (error) return kExitError;
    if (fail || missing) return kExitRegression;
    return kExitPass;
}

RunSummary run_suite(const RunOptions& o) {
    Suite suite = load_suite(o.suite);
    std::vector<TestCase> tests = select_tests(suite, o.filter, o.shard_index, o.shard_count);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    int jobs = o.jobs > 0 ? o.jobs : suite.jobs;
    jobs = std::max(1, std::min<int>(jobs, int(tests.size())));
    const int flip_threads = jobs > 1 ? 1 : 0;
    OutDirLock lock(o.out_dir);

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<json> results(tests.size());
    std::atomic<size_t> next{0};
    std::atomic<int> done{0};
    std::atomic<bool> shader_error{false};
    std::mutex print_mutex, driver_mutex;
    json driver;
    const bool interactive = isatty(STDOUT_FILENO);
    auto work = [&] {
        Worker w(o.device);
        for (size_t i; (i = next++) < tests.size();) {
            bool se = false;
            TestCase tc = tests[i];
            if (o.stability) tc.stability.enabled = true;
            results[i] = run_test(tc, w, store, o.out_dir, flip_threads, se);
            if (se) shader_error = true;
            int n = ++done;
            if (!o.quiet) {
                std::lock_guard lock(print_mutex);
                print_test_line(results[i], n, tests.size(), interactive);
            }
        }
        std::lock_guard lock(driver_mutex);
        if (json d = w.renderer.driver_json(); !d.empty()) driver = d;
    };
    std::vector<std::thread> pool;
    for (int j = 0; j < jobs; ++j) pool.emplace_back(work);
    for (auto& t : pool) t.join();

    RunSummary s;
    json& R = s.results;
    R = {{"schema", "iblcheck-results/1"}, {"suite", suite.name}, {"command", o.command_line}, {"started", utc_now_iso()}};
    R["total_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    json prov = run_provenance();
    std::string commit = prov["commit"];
    R["dirty"] = commit.size() > 6 && commit.substr(commit.size() - 6) == "-dirty";
    R["commit"] = R["dirty"].get<bool>() ? commit.substr(0, commit.size() - 6) : commit;
    R["driver"] = driver;
    R["cpu_features"] = prov["cpu_features"];
    R["cpu_class"] = prov["cpu_class"];
    R["shard"] = fmt::format("{}/{}", o.shard_index, o.shard_count);
    R["tests"] = json::array();
    for (auto& r : results) {
        Verdict v = parse_verdict(r["verdict"].get<std::string>());
        s.pass += v == Verdict::pass;
        s.fail += v == Verdict::fail;
        s.improved += v == Verdict::improved;
        s.missing += v == Verdict::missing_golden;
        s.error += v == Verdict::error;
        R["tests"].push_back(r);
    }
    R["counts"] = {{"pass", s.pass}, {"fail", s.fail}, {"improved", s.improved}, {"missing-golden", s.missing}, {"error", s.error}};
    s.shader_compile_error = shader_error;

    if (!o.out_dir.empty()) write_json_atomically(o.out_dir / "results.json", R);
    if (!o.json.empty()) write_json_atomically(o.json, R);
    if (!o.junit.empty()) write_junit(R, o.junit);
    std::vector<json> history;
    if (!o.history.empty()) {
        append_history(o.history, history_entry(R));
        history = read_history(o.history);
    }
    if (!o.out_dir.empty() && o.report) write_report(R, o.out_dir, o.out_dir, history);
    {  // -q drops the per-test lines, never this summary
        // The fp16 path mediump tests took (doctor states the same rule): native float16_t, or the
        // emulation on a driver without shaderFloat16 (e.g. a CPU without F16C).
        std::set<std::string> fp16;
        for (const json& r : R["tests"])
            if (r.contains("provenance") && r["provenance"].contains("fp16")) fp16.insert(r["provenance"]["fp16"].get<std::string>());
        for (const std::string& f : fp16)
            fmt::print("precision=mediump ran with {} fp16{}\n", f,
                       f == "emulated" ? " (no shaderFloat16: fp32 rounded to fp16 after every fp16 operation)" : " (float16_t)");
        fmt::print("{} tests: {} pass, {} fail, {} improved, {} missing-golden, {} error  ({:.1f} s){}\n", tests.size(),
                   s.pass, s.fail, s.improved, s.missing, s.error, R["total_s"].get<double>(),
                   o.out_dir.empty() ? "" : "  report: " + (o.out_dir / "index.html").string());
        if (s.fail + s.missing > 0)
            fmt::print("approve every failing result (after looking at them): iblcheck bless --suite '{}' --filter '{}'\n",
                       tests[0].suite_arg, o.filter.empty() ? "*" : o.filter);
    }
    return s;
}

} // namespace iblcheck
