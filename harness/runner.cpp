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
#include "reports/verdict_text.h"
#include "stability.h"
#include "temporal_check.h"
#include "verdict.h"
#include "worker.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// The image files of one test, under <out>/images/<test>/; results name them relative to <out>.
// Each image a person looks at is written twice: a PNG through the display transform (what SSIM
// measured) and a half-float EXR beside it, the linear data the report's exposure control, colour
// scale and exceedance mask work on.
struct Artefacts {
    fs::path dir;
    std::string rel; // "images/<test>/"
    explicit operator bool() const { return !dir.empty(); }
    static std::string exr(const std::string& png) { return png.substr(0, png.rfind('.')) + ".exr"; }
    std::string png(const std::string& name, const cv::Mat& linear, bool with_exr = true) const {
        fs::create_directories(dir);
        write_png((dir / name).string(), display_transform(linear));
        if (with_exr) write_exr_half((dir / exr(name)).string(), linear);
        return rel + name;
    }
    // A golden many tests compare with (a reference) as one half-float EXR per run under
    // images/_goldens/ (the same pixels are not written again for every test): its path.
    std::string shared_exr(const std::string& golden_rel, const cv::Mat& linear) const {
        const fs::path shared = dir.parent_path() / "_goldens";
        const std::string file = safe_file_name(golden_rel);
        if (!fs::exists(shared / file)) { // two workers (or processes) may both write it: same pixels, atomic rename
            fs::create_directories(shared);
            const fs::path tmp = shared / (file + fmt::format(".tmp{}-{}.exr", ::getpid(),
                                                              std::hash<std::thread::id>{}(std::this_thread::get_id())));
            write_exr_half(tmp.string(), linear);
            fs::rename(tmp, shared / file);
        }
        return "images/_goldens/" + file;
    }
    std::string heatmap(const std::string& name, const cv::Mat& errmap) const {
        fs::create_directories(dir);
        write_png((dir / name).string(), magma_heatmap(errmap));
        write_exr_half((dir / exr(name)).string(), errmap);
        return rel + name;
    }
    // A comparison's images: {test, golden, heatmap} PNGs and their EXRs (test_exr, golden_exr, error_exr).
    static json images(const std::string& test, const std::string& golden, const std::string& heatmap) {
        return {{"test", test},          {"golden", golden},          {"heatmap", heatmap},
                {"test_exr", exr(test)}, {"golden_exr", exr(golden)}, {"error_exr", exr(heatmap)}};
    }
    // Which sphere is where (the report names the sphere under the pointer): an 8-bit id map.
    json layout(const TestSpec& spec, int width, int height) const {
        SphereLayout l = sphere_layout(spec, width, height);
        if (l.ids.empty()) return nullptr;
        fs::create_directories(dir);
        cv::Mat ids;
        l.ids.convertTo(ids, CV_32F, 1.0 / 255.0);
        write_png((dir / "spheres.png").string(), ids);
        return {{"id_map", rel + "spheres.png"}, {"spheres", l.spheres}};
    }
};

// What the test is, before anything is rendered.
json test_header(const TestCase& tc) {
    return {{"name", tc.name},
            {"suite", tc.suite},
            {"scene", tc.spec.scene},
            {"method", tc.spec.method},
            {"env", tc.spec.env},
            {"options", tc.spec.options.values()},
            {"variant", tc.variant},
            {"tags", tc.tags},
            {"bless_command", bless_command(tc)},
            {"comparisons", json::array()},
            {"accuracy", nullptr},
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
    if (rr.texture_bytes > 0) { // the bytes/accuracy chart's x (mobile: the prefiltered chain)
        r["texture_bytes"] = rr.texture_bytes;
        r["texel_count"] = rr.texel_count;
    }
    r["cost"] = render_cost(rr);
    r["provenance"] = rr.provenance;
}

// Per-frame time of `repeats` renders in all (the first one already recorded in r): wall times
// vary 2-5x on a loaded machine, so the results keep every sample and report their median.
void repeat_timings(json& r, const TestCase& tc, Worker& w, int repeats) {
    if (repeats < 2) return;
    std::vector<double> frame{r["frame_ms"].get<double>()};
    for (int k = 1; k < repeats; ++k) {
        double f = 0;
        for (auto& p : w.renderer.render(tc.spec).timings) f += p.precompute ? 0 : p.ms;
        frame.push_back(f);
    }
    std::sort(frame.begin(), frame.end());
    const size_t n = frame.size();
    r["frame_ms_samples"] = frame;
    r["frame_ms"] = n % 2 ? frame[n / 2] : 0.5 * (frame[n / 2 - 1] + frame[n / 2]);
}

// Where the error concentrates, for a person: "worst 16x16 block at (160,16) on metal r=0.3 ...".
// Recorded on the comparison ({x, y, flip, sphere}); a failing comparison's message says it too.
void note_worst_block(Comparison& c, const TestSpec& spec, const FlipResult& flip, int width, int height) {
    std::string sphere =
        sphere_at(spec, width, height, std::min(flip.block_x + 8, width - 1), std::min(flip.block_y + 8, height - 1));
    c.worst_block = {{"x", flip.block_x}, {"y", flip.block_y}, {"flip", flip.block_max}, {"sphere", sphere}};
    if (c.verdict == Verdict::fail)
        c.message += fmt::format("; worst 16x16 block at ({},{}){} with mean FLIP {:.4g}", flip.block_x, flip.block_y,
                                 sphere.empty() ? "" : " on " + sphere, flip.block_max);
}

struct BaselineOutcome {
    Comparison comparison;
    bool missing = false;
    Golden golden; // the baseline judged against (empty image when missing)
};

// Any of the test's approved baselines may pass it; the report shows the one that did, or the
// closest one.
BaselineOutcome judge_against_baselines(const TestCase& tc, const cv::Mat& image, const GoldenStore& store, const Artefacts& art,
                                        int flip_threads) {
    BaselineOutcome out;
    std::vector<Golden> goldens = store.baselines(tc.name);
    if (goldens.empty()) {
        out.missing = true;
        out.comparison.kind = "baseline";
        out.comparison.verdict = Verdict::missing_golden;
        out.comparison.message =
            "no baseline golden at " + store.baseline_path(tc.name).string() + "; create it with: " + bless_command(tc);
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
            note_worst_block(c, tc.spec, flip, image.cols, image.rows);
            if (art) {
                std::string tag = g.label.empty() ? "baseline" : "baseline@" + safe_file_name(g.label);
                // A render bit-identical to its baseline (the usual pass) shares the test's EXR.
                const bool same = g.image.type() == image.type() && g.image.isContinuous() && image.isContinuous() &&
                                  std::memcmp(g.image.data, image.data, image.total() * image.elemSize()) == 0;
                c.images = Artefacts::images(art.rel + "test.png", art.png(tag + ".png", g.image, !same),
                                             art.heatmap(tag + "_flip.png", flip.errmap));
                if (same) c.images["golden_exr"] = c.images["test_exr"];
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
            Check c{"cost." + key,
                    value.get<double>(),
                    {},
                    {},
                    {},
                    Verdict::fail,
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
    note_worst_block(c, tc.spec, flip, image.cols, image.rows);
    r["accuracy"] = {{"flip_mean", flip.mean},
                     {"ssim", metrics["ssim"]["mean"]},
                     {"golden", c.golden},
                     {"noise_floor", ref.provenance.value("noise_floor", json())}};
    if (json ps = per_sphere_errors(tc.spec, flip.errmap); !ps.is_null()) r["per_sphere"] = ps;
    if (art) {
        c.images = Artefacts::images(art.rel + "test.png", art.png("reference.png", ref.image, false),
                                     art.heatmap("reference_flip.png", flip.errmap));
        c.images["golden_exr"] = art.shared_exr(c.golden, ref.image);
    }
    return c;
}

// The cost checks against the approved baseline (judge_costs), as one comparison of kind "cost".
Comparison cost_comparison(const TestCase& tc, const RenderResult& rr, const BaselineOutcome& base) {
    Comparison cost;
    cost.kind = "cost";
    cost.golden = base.comparison.golden;
    cost.checks = judge_costs(tc, rr, base.golden);
    for (const Check& k : cost.checks) {
        cost.message += k.message.empty() ? "" : (cost.message.empty() ? "" : "; ") + k.message;
        cost.verdict = overall_verdict({cost.verdict, k.status});
    }
    return cost;
}

// One test: render, compare, decide. Never throws: every outcome becomes a verdict.
json run_test(const TestCase& tc, Worker& w, const GoldenStore& store, const fs::path& out_dir, int flip_threads,
              int timing_repeats, bool& shader_error) {
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
        repeat_timings(r, tc, w, timing_repeats);
        if (NonFinite nf = find_non_finite(rr.image); nf.count) throw NonFiniteRender("render: " + nf.describe());
        if (art) {
            r["image"] = art.png("test.png", rr.image);
            r["image_exr"] = Artefacts::exr(r["image"]);
            r["layout"] = art.layout(tc.spec, rr.image.cols, rr.image.rows);
        }

        BaselineOutcome base;
        if (tc.baseline) {
            base = judge_against_baselines(tc, rr.image, store, art, flip_threads);
            r["comparisons"].push_back(to_json(base.comparison));
            if (!base.missing) r["comparisons"].back()["approved"] = baseline_facts(base.golden.provenance);
            add(base.comparison.verdict, base.missing                      ? base.comparison.message
                                         : base.comparison.message.empty() ? ""
                                                                           : "baseline: " + base.comparison.message);
            if (!base.missing) {
                const Comparison cost = cost_comparison(tc, rr, base);
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
            StabilityOutcome s =
                run_stability(tc, w, rr.image, reference, base.golden.provenance.value("accuracy", json()), flip_threads);
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
                                         "another --out",
                                         dir.string(), n > 0 ? fmt::format(" (pid {})", buf) : ""));
        }
        std::string pid = std::to_string(::getpid());
        if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {}
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
    fmt::print("{}[{:>3}/{}] {:<15} {}{}  ({:.1f} s)\n", interactive ? "\r" : "", n, total, v, r["name"].get<std::string>(), acc,
               r["wall_s"].get<double>());
    for (const std::string& line : verdict_details(r)) fmt::print("          {}\n", line);
    std::fflush(stdout);
}

// The lines every run prints, -q or not: the fp16 path mediump tests took, the counts, and the
// command that approves every failure.
void print_run_summary(const json& R, const RunSummary& s, size_t n_tests, const RunOptions& o, const std::string& suite_arg) {
    // The fp16 path mediump tests took (doctor states the same rule): native float16_t, or the
    // emulation on a driver without shaderFloat16 (e.g. a CPU without F16C).
    std::set<std::string> fp16;
    for (const json& r : R["tests"])
        if (r.contains("provenance") && r["provenance"].contains("fp16")) fp16.insert(r["provenance"]["fp16"].get<std::string>());
    for (const std::string& f : fp16)
        fmt::print("precision=mediump ran with {} fp16{}\n", f,
                   f == "emulated" ? " (no shaderFloat16: fp32 rounded to fp16 after every fp16 operation)" : " (float16_t)");
    fmt::print("{} tests: {} pass, {} fail, {} improved, {} missing-golden, {} error  ({:.1f} s){}\n", n_tests, s.pass, s.fail,
               s.improved, s.missing, s.error, R["total_s"].get<double>(),
               o.out_dir.empty() ? "" : "  report: " + (o.out_dir / "index.html").string());
    if (std::string all = rebless_all_line(R["tests"], suite_arg); !all.empty()) fmt::print("{}\n", all);
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
            results[i] = run_test(tc, w, store, o.out_dir, flip_threads, suite.timing_repeats, se);
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
    R["counts"] = {
        {"pass", s.pass}, {"fail", s.fail}, {"improved", s.improved}, {"missing-golden", s.missing}, {"error", s.error}};
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
    print_run_summary(R, s, tests.size(), o, tests[0].suite_arg); // -q drops the per-test lines, never this summary
    return s;
}

} // namespace iblcheck
