#include "runner.h"

#include <fmt/core.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <thread>
#include <unistd.h>

#include "harness/common/errors.h"
#include "harness/common/markup.h"
#include "metrics/display_transform.h"
#include "metrics/flip.h"
#include "metrics/image_io.h"
#include "metrics/psnr.h"
#include "metrics/ssim.h"
#include "metrics/temporal.h"
#include "renderers/renderer.h"
#include "renderers/scenes/scene.h"

#include "reports/report_writer.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// Metrics of `test` against `golden` as results JSON (the same keys `iblcheck compare --json` prints).
json compare_images(const cv::Mat& golden, const cv::Mat& test, int flip_threads, FlipResult* flip_out = nullptr) {
    FlipOptions fo;
    fo.threads = flip_threads;
    FlipResult f = compute_flip_hdr(golden, test, fo);
    SsimResult s = compute_ssim_hdr(golden, test);
    PsnrResult p = compute_psnr(display_transform(golden), display_transform(test));
    json j;
    j["flip"] = {{"mean", f.mean}, {"weighted_median", f.weighted_median}, {"weighted_q1", f.weighted_q1},
                 {"weighted_q3", f.weighted_q3}, {"p99", f.p99}, {"min", f.min}, {"max", f.max},
                 {"block_max", f.block_max}, {"block_x", f.block_x}, {"block_y", f.block_y}, {"mode", f.mode},
                 {"start_exposure", f.start_exposure}, {"stop_exposure", f.stop_exposure},
                 {"num_exposures", f.num_exposures}};
    j["ssim"] = {{"mean", s.mean}};
    j["psnr"] = {{"db", std::isfinite(p.db) ? json(p.db) : json(999.0)}, {"rmse", p.rmse}, {"max_abs", p.max_abs}};
    if (flip_out) *flip_out = std::move(f);
    return j;
}

double metric_value(const json& metrics, const std::string& key) {
    auto dot = key.find('.');
    return metrics.at(key.substr(0, dot)).at(key.substr(dot + 1)).get<double>();
}

// Larger is better for SSIM and PSNR, smaller for FLIP.
bool higher_is_better(const std::string& metric) { return metric.rfind("ssim", 0) == 0 || metric.rfind("psnr", 0) == 0; }

std::string fmt_num(double v) { return fmt::format("{:.4g}", v); }

// Pixel → sphere index (−1 for background), from the same camera and intersection the renderers use.
cv::Mat sphere_id_map(const TestSpec& spec, int width, int height) {
    Scene scene = build_scene(spec.scene, spec.options);
    cv::Mat ids(height, width, CV_32S);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            Vec3f o, d;
            camera_ray(scene, width, height, x + 0.5, y + 0.5, o, d);
            Hit h = intersect(scene, o, d);
            ids.at<int>(y, x) = h.hit ? h.sphere : -1;
        }
    return ids;
}

json per_sphere_errors(const TestSpec& spec, const cv::Mat& errmap) {
    Scene scene = build_scene(spec.scene, spec.options);
    if (scene.spheres.size() < 2) return json();
    cv::Mat ids = sphere_id_map(spec, errmap.cols, errmap.rows);
    std::vector<double> sum(scene.spheres.size(), 0.0);
    std::vector<long> count(scene.spheres.size(), 0);
    for (int y = 0; y < errmap.rows; ++y)
        for (int x = 0; x < errmap.cols; ++x) {
            int id = ids.at<int>(y, x);
            if (id < 0) continue;
            sum[size_t(id)] += errmap.at<float>(y, x);
            count[size_t(id)]++;
        }
    json out = json::array();
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        if (!count[i]) continue;
        out.push_back({{"label", i < scene.labels.size() ? scene.labels[i] : std::to_string(i)},
                       {"roughness", scene.spheres[i].material.roughness},
                       {"metallic", scene.spheres[i].material.metallic},
                       {"flip_mean", sum[i] / double(count[i])}});
    }
    return out;
}

struct Worker {
    explicit Worker(const std::string& device) : renderer([&] {
        vk::ContextOptions o;
        o.device = device;
        return o;
    }()) {}
    Renderer renderer;
    // Tone-mapped frames of sequences already rendered (the reference and `off` sequences are shared
    // by every variant of a scene).
    std::map<std::string, std::vector<cv::Mat>> sequences;

    const std::vector<cv::Mat>& sequence(TestSpec spec, int frames) {
        std::string key = spec.method + "|" + spec.scene + "|" + spec.env + "|" + std::to_string(spec.width) + "x" +
                          std::to_string(spec.height) + "|" + spec.options.canonical() + "|" + std::to_string(frames);
        auto it = sequences.find(key);
        if (it != sequences.end()) return it->second;
        std::vector<cv::Mat> out;
        for (int f = 0; f < frames; ++f) {
            spec.options.set("frame", std::to_string(f));
            cv::Mat img = renderer.render(spec).image;
            check_finite(img, spec.scene + " frame " + std::to_string(f));
            out.push_back(display_transform(img));
        }
        return sequences.emplace(key, std::move(out)).first->second;
    }
};

struct SequenceScore {
    double flicker = 0, variation_ratio = 0, flip_mean = 0;
};
SequenceScore score_sequence(const std::vector<cv::Mat>& test, const std::vector<cv::Mat>& ref, int flip_threads) {
    SequenceScore s;
    TemporalResult t = compute_temporal(test, ref);
    s.flicker = t.flicker;
    s.variation_ratio = t.variation_ratio;
    FlipOptions fo;
    fo.threads = flip_threads;
    for (size_t i = 0; i < test.size(); ++i) s.flip_mean += compute_flip_ldr(ref[i], test[i], fo).mean;
    s.flip_mean /= double(test.size());
    return s;
}

// Renders the test's sequence, its `off` sequence and the reference sequence; scores and checks them.
// Appends failures to `problems`; returns the "temporal" results object.
json run_temporal(const TestCase& tc, Worker& w, const fs::path& img_dir, int flip_threads, bool& failed,
                  std::vector<std::string>& problems) {
    const TemporalSpec& ts = tc.temporal;
    TestSpec off = tc.spec, ref = tc.spec;
    off.options.set("specular_aa", "off");
    ref.options.set("specular_aa", "off");
    ref.options.set("ssaa", std::to_string(ts.reference_ssaa * tc.spec.options.get_int("ssaa", 2)));
    const auto& test_frames = w.sequence(tc.spec, ts.frames);
    const auto& off_frames = w.sequence(off, ts.frames);
    const auto& ref_frames = w.sequence(ref, ts.frames);
    SequenceScore st = score_sequence(test_frames, ref_frames, flip_threads);
    SequenceScore so = score_sequence(off_frames, ref_frames, flip_threads);
    json j = {{"frames_count", ts.frames},
              {"flicker", st.flicker},
              {"variation_ratio", st.variation_ratio},
              {"flip_mean", st.flip_mean},
              {"off", {{"flicker", so.flicker}, {"variation_ratio", so.variation_ratio}, {"flip_mean", so.flip_mean}}},
              {"flicker_ratio", so.flicker > 0 ? st.flicker / so.flicker : 1.0},
              {"flip_ratio", so.flip_mean > 0 ? st.flip_mean / so.flip_mean : 1.0}};
    j["checks"] = json::array();
    for (auto& [metric, bound] : ts.checks) {
        double v = j[metric].get<double>();
        bool ok = (!bound.min || v >= *bound.min) && (!bound.max || v <= *bound.max);
        j["checks"].push_back({{"metric", "temporal." + metric}, {"value", v},
                               {"min", bound.min ? json(*bound.min) : json()},
                               {"max", bound.max ? json(*bound.max) : json()}, {"status", ok ? "pass" : "fail"}});
        if (!ok) {
            failed = true;
            problems.push_back(fmt::format("temporal: {} {} outside [{}, {}]", metric, fmt_num(v),
                                           bound.min ? fmt_num(*bound.min) : "-inf", bound.max ? fmt_num(*bound.max) : "inf"));
        }
    }
    if (!img_dir.empty()) {
        fs::create_directories(img_dir);
        std::string base = "images/" + img_dir.filename().string() + "/";
        for (int f = 0; f < ts.frames; ++f) {
            std::string tf = fmt::format("frame{:03d}.png", f), rf = fmt::format("ref{:03d}.png", f);
            write_png((img_dir / tf).string(), test_frames[size_t(f)]);
            write_png((img_dir / rf).string(), ref_frames[size_t(f)]);
            j["frames"].push_back(base + tf);
            j["reference_frames"].push_back(base + rf);
        }
    }
    return j;
}

void write_test_png(const fs::path& dir, const std::string& name, const cv::Mat& linear) {
    fs::create_directories(dir);
    write_png((dir / name).string(), display_transform(linear));
}

json timings_json(const RenderResult& r, double& precompute_ms, double& frame_ms) {
    json t = json::array();
    precompute_ms = frame_ms = 0;
    for (auto& p : r.timings) {
        t.push_back({{"pass", p.name}, {"ms", p.ms}, {"gpu", p.gpu}, {"precompute", p.precompute}});
        (p.precompute ? precompute_ms : frame_ms) += p.ms;
    }
    return t;
}

bool bit_identical(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

std::mutex& environment_mutex() {
    static std::mutex m;
    return m;
}

// Renders `spec` in a fresh Vulkan instance with lavapipe limited to one thread (LP_NUM_THREADS is
// read when the driver's screen is created). The process environment is shared, hence the lock.
cv::Mat render_single_threaded(const TestSpec& spec, const std::string& device) {
    std::lock_guard lock(environment_mutex());
    const char* old = std::getenv("LP_NUM_THREADS");
    std::string saved = old ? old : "";
    setenv("LP_NUM_THREADS", "1", 1);
    cv::Mat img;
    try {
        vk::ContextOptions o;
        o.device = device;
        Renderer r(o);
        img = r.render(spec).image;
    } catch (...) {
        old ? setenv("LP_NUM_THREADS", saved.c_str(), 1) : unsetenv("LP_NUM_THREADS");
        throw;
    }
    old ? setenv("LP_NUM_THREADS", saved.c_str(), 1) : unsetenv("LP_NUM_THREADS");
    return img;
}

bool monte_carlo(const TestSpec& spec) { return spec.method == "sampled" || spec.method == "reference"; }

// Stability of one test (issue 9). `base` is the render the verdict used, `golden` the baseline it
// was compared with (may be empty), `reference` the reference golden (may be empty).
json run_stability(const TestCase& tc, Worker& w, const cv::Mat& base, const cv::Mat& golden, const cv::Mat& reference,
                   const json& approved_accuracy, int flip_threads, const std::string& device, bool& flaky) {
    const StabilitySpec& st = tc.stability;
    json j;
    // 1. Determinism: repeats in this instance, and one render with one lavapipe thread.
    bool deterministic = true;
    std::string how;
    for (int k = 1; k < st.repeats; ++k)
        if (!bit_identical(w.renderer.render(tc.spec).image, base)) {
            deterministic = false;
            how = "repeat " + std::to_string(k) + " differs";
        }
    if (st.thread_counts && tc.spec.method != "reference" &&
        !bit_identical(render_single_threaded(tc.spec, device), base)) {
        deterministic = false;
        how += (how.empty() ? "" : "; ") + std::string("LP_NUM_THREADS=1 differs");
    }
    if (tc.spec.method == "reference") {
        TestSpec one = tc.spec;
        one.options.set("threads", "1");
        if (!bit_identical(w.renderer.render(one).image, base)) {
            deterministic = false;
            how += (how.empty() ? "" : "; ") + std::string("threads=1 differs");
        }
    }
    j["deterministic"] = deterministic;
    if (!deterministic) j["nondeterminism"] = how;

    // 2. Noise floors: Monte Carlo methods over seeds; each metric's spread against the baseline
    // and the accuracy's spread against the reference golden.
    std::map<std::string, double> floor;
    std::vector<cv::Mat> variants;
    if (monte_carlo(tc.spec))
        for (int s = 1; s < st.seeds; ++s) {
            TestSpec seeded = tc.spec;
            seeded.options.set("seed", std::to_string(tc.spec.options.get_int("seed", 0) + s));
            variants.push_back(w.renderer.render(seeded).image);
        }
    auto spread = [&](const cv::Mat& against, const std::string& prefix) {
        if (against.empty() || against.size() != base.size()) return;
        json m0 = compare_images(against, base, flip_threads);
        for (const cv::Mat& v : variants) {
            json m = compare_images(against, v, flip_threads);
            for (const char* k : {"flip.mean", "flip.p99", "flip.block_max", "ssim.mean"}) {
                double d = std::fabs(metric_value(m, k) - metric_value(m0, k));
                floor[prefix + k] = std::max(floor[prefix + k], d);
            }
            // Against the baseline itself the seed change is the whole difference.
            if (prefix.empty())
                for (const char* k : {"flip.mean", "flip.p99", "flip.block_max"})
                    floor[k] = std::max(floor[k], metric_value(compare_images(base, v, flip_threads), k));
        }
    };
    spread(golden, "");
    spread(reference, "accuracy.");
    j["noise_floor"] = floor;
    j["seeds"] = monte_carlo(tc.spec) ? st.seeds : 1;

    // 3. Sensitivity: what a quarter-pixel camera shift or a 1e-3 roughness change does.
    json sens;
    for (auto [key, value] : {std::pair<std::string, std::string>{"camera_shift", fmt::format("{},{},0", st.camera_shift, st.camera_shift)},
                              std::pair<std::string, std::string>{"roughness_bias", fmt::format("{}", st.roughness_bias)}}) {
        TestSpec p = tc.spec;
        p.options.set(key, value);
        json m = compare_images(base, w.renderer.render(p).image, flip_threads);
        sens[key] = {{"value", value}, {"flip.mean", m["flip"]["mean"]}, {"flip.p99", m["flip"]["p99"]},
                     {"flip.block_max", m["flip"]["block_max"]}, {"ssim.mean", m["ssim"]["mean"]}};
    }
    j["sensitivity"] = sens;

    // 4. Margins: tolerance / noise floor (null when the floor is 0: a deterministic render).
    json margins = json::object();
    flaky = false;
    auto margin = [&](const std::string& name, double width, double nf) {
        if (nf <= 0) {
            margins[name] = nullptr;
            return;
        }
        double m = width / nf;
        margins[name] = m;
        if (m < st.min_margin) flaky = true;
    };
    for (auto& [metric, bound] : tc.baseline_tolerances) {
        if (!floor.count(metric)) continue;
        if (bound.max) margin(metric, *bound.max, floor[metric]);
        else if (bound.min) margin(metric, 1.0 - *bound.min, floor[metric]);
    }
    for (auto& [metric, band] : tc.reference_band) {
        std::string key = "accuracy." + metric;
        if (!floor.count(key) || !approved_accuracy.is_object() || !approved_accuracy.contains(metric)) continue;
        double a = approved_accuracy[metric].get<double>();
        margin(key, std::min(a * band.below, a * band.above) + band.abs, floor[key]);
    }
    j["margins"] = margins;
    j["min_margin"] = st.min_margin;
    j["flaky"] = flaky;
    return j;
}

// One test: render, compare, decide. Never throws: failures become verdicts.
json run_test(const TestCase& tc, Worker& w, const GoldenStore& store, const fs::path& out_dir, int flip_threads,
              bool& shader_error, const std::string& device) {
    json r;
    r["name"] = tc.name;
    r["suite"] = tc.suite;
    r["scene"] = tc.spec.scene;
    r["method"] = tc.spec.method;
    r["env"] = tc.spec.env;
    r["options"] = tc.spec.options.values();
    r["variant"] = tc.variant;
    r["tags"] = tc.tags;
    r["bless_command"] = bless_command(tc);
    r["comparisons"] = json::array();
    r["accuracy"] = nullptr;
    r["driver_mismatch"] = nullptr;
    fs::path img_dir = out_dir.empty() ? fs::path() : out_dir / "images" / safe_file_name(tc.name);
    auto rel = [&](const std::string& f) { return ("images/" + safe_file_name(tc.name) + "/" + f); };
    auto t0 = std::chrono::steady_clock::now();
    try {
        RenderResult rr = w.renderer.render(tc.spec);
        r["width"] = rr.image.cols;
        r["height"] = rr.image.rows;
        double pre = 0, frame = 0;
        r["timings"] = timings_json(rr, pre, frame);
        r["precompute_ms"] = pre;
        r["frame_ms"] = frame;
        r["texture_fetches_per_pixel"] = rr.texture_fetches_per_pixel;
        r["provenance"] = rr.provenance;
        check_finite(rr.image, tc.name + " (render)");
        if (!img_dir.empty()) {
            write_test_png(img_dir, "test.png", rr.image);
            r["image"] = rel("test.png");
        }

        std::vector<std::string> problems;
        bool any_fail = false, improved = false, missing = false;
        const std::string driver_now = rr.provenance.value("driver", json::object()).value("driver_info", "");

        // 1. Approved baselines: pass against any of them.
        json approved_accuracy;
        cv::Mat matched_golden, reference_image;
        if (tc.baseline) {
            auto goldens = store.baselines(tc.name);
            if (goldens.empty()) {
                missing = true;
                problems.push_back("no baseline golden at " + store.baseline_path(tc.name).string() + "; create it with: " +
                                   bless_command(tc));
            }
            json best;
            bool passed_one = false;
            for (auto& g : goldens) {
                json c;
                c["kind"] = "baseline";
                c["golden"] = g.image_path.string();
                c["label"] = g.label;
                if (g.image.size() != rr.image.size()) {
                    c["verdict"] = "fail";
                    c["checks"] = json::array({{{"metric", "size"}, {"status", "fail"},
                                                {"value", fmt::format("{}x{}", rr.image.cols, rr.image.rows)},
                                                {"expected", fmt::format("{}x{}", g.image.cols, g.image.rows)}}});
                    if (best.is_null()) best = c;
                    continue;
                }
                FlipResult flip;
                c["metrics"] = compare_images(g.image, rr.image, flip_threads, &flip);
                c["checks"] = json::array();
                bool ok = true;
                std::string why;
                for (auto& [metric, bound] : tc.baseline_tolerances) {
                    double v = metric_value(c["metrics"], metric);
                    std::string status = "pass";
                    if (bound.max && v > *bound.max) {
                        status = "fail";
                        why += fmt::format("{} {} > {} (+{}); ", metric, fmt_num(v), fmt_num(*bound.max), fmt_num(v - *bound.max));
                    }
                    if (bound.min && v < *bound.min) {
                        status = "fail";
                        why += fmt::format("{} {} < {} (-{}); ", metric, fmt_num(v), fmt_num(*bound.min), fmt_num(*bound.min - v));
                    }
                    ok &= status == "pass";
                    c["checks"].push_back({{"metric", metric}, {"value", v},
                                           {"min", bound.min ? json(*bound.min) : json()},
                                           {"max", bound.max ? json(*bound.max) : json()}, {"status", status}});
                }
                c["verdict"] = ok ? "pass" : "fail";
                if (!ok) c["message"] = why + fmt::format("worst 16x16 block at ({},{}) with mean FLIP {}", flip.block_x,
                                                          flip.block_y, fmt_num(flip.block_max));
                std::string golden_driver = g.provenance.value("driver", json::object()).value("driver_info", "");
                if (!golden_driver.empty() && !driver_now.empty() && golden_driver != driver_now)
                    r["driver_mismatch"] = "golden made with " + golden_driver + ", this run " + driver_now;
                if (!img_dir.empty()) {
                    std::string tag = g.label.empty() ? "baseline" : "baseline@" + safe_file_name(g.label);
                    write_test_png(img_dir, tag + ".png", g.image);
                    write_png((img_dir / (tag + "_flip.png")).string(), magma_heatmap(flip.errmap));
                    c["images"] = {{"test", rel("test.png")}, {"golden", rel(tag + ".png")}, {"heatmap", rel(tag + "_flip.png")}};
                }
                if (ok && !passed_one) {
                    passed_one = true;
                    matched_golden = g.image;
                    best = c;
                    approved_accuracy = g.provenance.value("accuracy", json());
                } else if (!passed_one && (best.is_null() || !best.contains("metrics") ||
                                           c["metrics"]["flip"]["mean"].get<double>() < best["metrics"]["flip"]["mean"].get<double>())) {
                    best = c;
                }
            }
            if (!goldens.empty()) {
                r["comparisons"].push_back(best);
                if (!passed_one) {
                    any_fail = true;
                    problems.push_back("baseline: " + best.value("message", std::string("size differs")));
                }
            }
        }

        // 2. Accuracy against the reference golden, checked against the band approved at bless time.
        if (tc.reference) {
            if (auto ref = store.reference(tc.spec)) {
                reference_image = ref->image;
                json c;
                c["kind"] = "reference";
                c["golden"] = ref->image_path.string();
                if (ref->image.size() != rr.image.size()) {
                    c["verdict"] = "fail";
                    problems.push_back("reference golden " + ref->image_path.string() + " has another size");
                    any_fail = true;
                } else {
                    FlipResult flip;
                    c["metrics"] = compare_images(ref->image, rr.image, flip_threads, &flip);
                    r["accuracy"] = {{"flip_mean", flip.mean}, {"ssim", c["metrics"]["ssim"]["mean"]},
                                     {"golden", ref->image_path.string()},
                                     {"noise_floor", ref->provenance.value("noise_floor", json())}};
                    json ps = per_sphere_errors(tc.spec, flip.errmap);
                    if (!ps.is_null()) r["per_sphere"] = ps;
                    c["checks"] = json::array();
                    std::string verdict = "pass";
                    for (auto& [metric, band] : tc.reference_band) {
                        if (!approved_accuracy.is_object() || !approved_accuracy.contains(metric)) continue;
                        double approved = approved_accuracy[metric].get<double>();
                        double v = metric_value(c["metrics"], metric);
                        bool hib = higher_is_better(metric);
                        double lo = approved * (1 - band.below) - band.abs, hi = approved * (1 + band.above) + band.abs;
                        std::string status = "pass";
                        if (v > hi) status = hib ? "improved" : "fail";
                        if (v < lo) status = hib ? "fail" : "improved";
                        if (status == "fail") {
                            any_fail = true;
                            problems.push_back(fmt::format("accuracy: {} {} outside [{}, {}] approved around {}; worst block at ({},{})",
                                                           metric, fmt_num(v), fmt_num(lo), fmt_num(hi), fmt_num(approved),
                                                           flip.block_x, flip.block_y));
                            verdict = "fail";
                        } else if (status == "improved") {
                            improved = true;
                            problems.push_back(fmt::format("accuracy improved: {} {} beyond [{}, {}]: tighten by re-blessing",
                                                           metric, fmt_num(v), fmt_num(lo), fmt_num(hi)));
                            if (verdict == "pass") verdict = "improved";
                        }
                        c["checks"].push_back({{"metric", metric}, {"value", v}, {"min", lo}, {"max", hi}, {"status", status},
                                               {"approved", approved}});
                    }
                    c["verdict"] = verdict;
                    if (!img_dir.empty()) {
                        write_test_png(img_dir, "reference.png", ref->image);
                        write_png((img_dir / "reference_flip.png").string(), magma_heatmap(flip.errmap));
                        c["images"] = {{"test", rel("test.png")}, {"golden", rel("reference.png")}, {"heatmap", rel("reference_flip.png")}};
                    }
                }
                r["comparisons"].push_back(c);
            }
        }

        // 3. Temporal sequences.
        if (tc.temporal.frames > 0) r["temporal"] = run_temporal(tc, w, img_dir, flip_threads, any_fail, problems);

        // 4. Stability: determinism, noise floors, sensitivity, margins.
        if (tc.stability.enabled) {
            bool flaky = false;
            if (matched_golden.empty() && tc.baseline) {
                auto goldens = store.baselines(tc.name);
                if (!goldens.empty()) matched_golden = goldens[0].image;
            }
            r["stability"] = run_stability(tc, w, rr.image, matched_golden, reference_image, approved_accuracy,
                                           flip_threads, device, flaky);
            if (!r["stability"]["deterministic"].get<bool>()) {
                any_fail = true;
                problems.push_back("not deterministic: " + r["stability"]["nondeterminism"].get<std::string>());
            }
            if (flaky) {
                std::string which;
                for (auto& [k, v] : r["stability"]["margins"].items())
                    if (v.is_number() && v.get<double>() < tc.stability.min_margin) which += fmt::format("{} margin {:.2f}; ", k, v.get<double>());
                problems.push_back("flaky: tolerance under " + fmt_num(tc.stability.min_margin) + "x its noise floor: " + which);
                if (tc.stability.fail_on_flaky) any_fail = true;
            }
        }

        std::string verdict = missing ? "missing-golden" : any_fail ? "fail" : improved ? "improved" : "pass";
        r["verdict"] = verdict;
        std::string msg;
        for (auto& p : problems) msg += (msg.empty() ? "" : "; ") + p;
        r["message"] = msg;
        if (verdict != "pass" && !img_dir.empty()) write_exr((img_dir / "test.exr").string(), rr.image);
    } catch (const ShaderCompileError& e) {
        shader_error = true;
        r["verdict"] = "error";
        r["message"] = std::string("shader compile failed: ") + e.what();
    } catch (const std::exception& e) {
        r["verdict"] = "error";
        r["message"] = e.what();
    }
    r["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}


} // namespace

std::string bless_command(const TestCase& t) {
    return "iblcheck bless --suite " + t.suite + " --filter '" + t.name + "'";
}

int RunSummary::exit_code() const {
    if (error) return kExitError;
    if (fail || missing) return kExitRegression;
    return kExitPass;
}

void write_junit(const json& results, const fs::path& file) {
    const json& tests = results.at("tests");
    int failures = 0, errors = 0;
    for (auto& t : tests) {
        std::string v = t.value("verdict", "error");
        failures += v == "fail" || v == "missing-golden";
        errors += v == "error";
    }
    std::string suite = results.value("suite", "iblcheck");
    std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x += fmt::format("<testsuites name=\"iblcheck\" tests=\"{}\" failures=\"{}\" errors=\"{}\" time=\"{:.3f}\">\n",
                     tests.size(), failures, errors, results.value("total_s", 0.0));
    x += fmt::format("  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"0\" time=\"{:.3f}\" timestamp=\"{}\">\n",
                     escape_markup(suite), tests.size(), failures, errors, results.value("total_s", 0.0),
                     escape_markup(results.value("started", "")));
    for (auto& t : tests) {
        std::string name = t.value("name", "?"), v = t.value("verdict", "error"), msg = t.value("message", "");
        x += fmt::format("    <testcase classname=\"{}.{}\" name=\"{}\" time=\"{:.3f}\">", escape_markup(suite),
                         escape_markup(t.value("method", "")), escape_markup(name), t.value("wall_s", 0.0));
        if (v == "fail" || v == "missing-golden")
            x += fmt::format("\n      <failure type=\"{}\" message=\"{}\">{}\nrebless: {}</failure>\n    ", v, escape_markup(msg),
                             escape_markup(msg), escape_markup(t.value("bless_command", "")));
        else if (v == "error")
            x += fmt::format("\n      <error type=\"error\" message=\"{}\">{}</error>\n    ", escape_markup(msg), escape_markup(msg));
        else if (v == "improved")
            x += fmt::format("\n      <system-out>improved: {}</system-out>\n    ", escape_markup(msg));
        x += "</testcase>\n";
    }
    x += "  </testsuite>\n</testsuites>\n";
    if (!file.parent_path().empty()) fs::create_directories(file.parent_path());
    std::ofstream f(file);
    f << x;
    if (!f) throw InputError(file.string() + ": cannot write JUnit XML");
}

RunSummary run_suite(const RunOptions& o) {
    Suite suite = load_suite(o.suite);
    std::vector<TestCase> tests = select_tests(suite, o.filter, o.shard_index, o.shard_count);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    int jobs = o.jobs > 0 ? o.jobs : suite.jobs;
    jobs = std::max(1, std::min<int>(jobs, int(tests.size())));
    int flip_threads = jobs > 1 ? 1 : 0;
    if (!o.out_dir.empty()) fs::create_directories(o.out_dir);

    auto t0 = std::chrono::steady_clock::now();
    std::vector<json> results(tests.size());
    std::atomic<size_t> next{0};
    std::atomic<int> done{0};
    std::atomic<bool> shader_error{false};
    std::mutex print_mutex;
    json driver;
    std::mutex driver_mutex;
    bool interactive = isatty(STDOUT_FILENO);
    auto work = [&] {
        Worker w(o.device);
        for (size_t i; (i = next++) < tests.size();) {
            bool se = false;
            TestCase tc = tests[i];
            if (o.stability) tc.stability.enabled = true;
            results[i] = run_test(tc, w, store, o.out_dir, flip_threads, se, o.device);
            if (se) shader_error = true;
            int n = ++done;
            if (!o.quiet) {
                std::lock_guard lock(print_mutex);
                const json& r = results[i];
                std::string acc = r["accuracy"].is_object() ? fmt::format("  vs truth {:.4f}", r["accuracy"]["flip_mean"].get<double>()) : "";
                fmt::print("{}[{:>3}/{}] {:<15} {}{}  ({:.1f} s)\n", interactive ? "\r" : "", n, tests.size(),
                           r["verdict"].get<std::string>(), r["name"].get<std::string>(), acc, r["wall_s"].get<double>());
                if (r["verdict"] != "pass" && !r["message"].get<std::string>().empty())
                    fmt::print("          {}\n", r["message"].get<std::string>());
                std::fflush(stdout);
            }
        }
        std::lock_guard lock(driver_mutex);
        json d = w.renderer.driver_json();
        if (!d.empty()) driver = d;
    };
    std::vector<std::thread> pool;
    for (int j = 0; j < jobs; ++j) pool.emplace_back(work);
    for (auto& t : pool) t.join();

    RunSummary s;
    bool dirty = false;
    json& R = s.results;
    R["schema"] = "iblcheck-results/1";
    R["suite"] = suite.name;
    R["command"] = o.command_line;
    R["started"] = utc_now_iso();
    R["total_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    R["commit"] = project_commit(&dirty);
    R["dirty"] = dirty;
    R["driver"] = driver;
    R["cpu_features"] = cpu_features();
    R["shard"] = fmt::format("{}/{}", o.shard_index, o.shard_count);
    R["tests"] = json::array();
    for (auto& r : results) {
        std::string v = r["verdict"];
        s.pass += v == "pass";
        s.fail += v == "fail";
        s.improved += v == "improved";
        s.missing += v == "missing-golden";
        s.error += v == "error";
        R["tests"].push_back(r);
    }
    R["counts"] = {{"pass", s.pass}, {"fail", s.fail}, {"improved", s.improved}, {"missing-golden", s.missing}, {"error", s.error}};
    s.shader_compile_error = shader_error;

    if (!o.out_dir.empty()) {
        std::ofstream f(o.out_dir / "results.json");
        f << R.dump(1) << "\n";
    }
    if (!o.json.empty()) {
        std::ofstream f(o.json);
        f << R.dump(1) << "\n";
        if (!f) throw InputError(o.json.string() + ": cannot write results JSON");
    }
    if (!o.junit.empty()) write_junit(R, o.junit);
    std::vector<json> history;
    if (!o.history.empty()) {
        append_history(o.history, history_entry(R));
        history = read_history(o.history);
    }
    if (!o.out_dir.empty() && o.report) write_report(R, o.out_dir, o.out_dir, history);
    if (!o.quiet)
        fmt::print("{} tests: {} pass, {} fail, {} improved, {} missing-golden, {} error  ({:.1f} s){}\n", tests.size(), s.pass,
                   s.fail, s.improved, s.missing, s.error, R["total_s"].get<double>(),
                   o.out_dir.empty() ? "" : "  report: " + (o.out_dir / "index.html").string());
    return s;
}

int bless(const BlessOptions& o) {
    Suite suite = load_suite(o.suite);
    std::vector<TestCase> tests = select_tests(suite, o.filter, 0, 1);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    Worker w(o.device);
    int failed = 0;
    bool dirty = false;
    std::string commit = project_commit(&dirty);
    for (const auto& tc : tests) {
        if (!tc.baseline) continue;
        RenderResult rr;
        try {
            rr = w.renderer.render(tc.spec);
            check_finite(rr.image, tc.name + " (render)");
        } catch (const std::exception& e) {
            fmt::print(stderr, "error: {}: render failed, not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        json accuracy = json::object();
        if (auto ref = store.reference(tc.spec); ref && ref->image.size() == rr.image.size()) {
            json m = compare_images(ref->image, rr.image, 0);
            accuracy = {{"flip.mean", m["flip"]["mean"]}, {"flip.p99", m["flip"]["p99"]}, {"flip.block_max", m["flip"]["block_max"]},
                        {"ssim.mean", m["ssim"]["mean"]}, {"psnr.db", m["psnr"]["db"]}};
        }
        fs::path path = store.baseline_path(tc.name, o.label);
        std::string change = "new";
        if (fs::exists(path)) {
            cv::Mat old = read_image(path.string()).pixels;
            if (old.size() == rr.image.size()) {
                json m = compare_images(old, rr.image, 0);
                double d = m["flip"]["mean"];
                change = d == 0 && m["psnr"]["db"].get<double>() >= 999 ? "unchanged"
                                                                         : fmt::format("changed: FLIP vs old baseline {:.5f}", d);
            } else {
                change = "changed size";
            }
            std::ifstream f(fs::path(path).replace_extension(".json"));
            json oldp = json::parse(f, nullptr, false);
            if (oldp.is_object() && oldp.contains("accuracy") && accuracy.contains("flip.mean") &&
                oldp["accuracy"].contains("flip.mean"))
                change += fmt::format("; accuracy FLIP {:.5f} -> {:.5f}", oldp["accuracy"]["flip.mean"].get<double>(),
                                      accuracy["flip.mean"].get<double>());
        }
        json prov = rr.provenance;
        prov["test"] = tc.name;
        prov["suite"] = tc.suite;
        prov["method"] = tc.spec.method;
        prov["variant"] = tc.variant;
        prov["size"] = {rr.image.cols, rr.image.rows};
        prov["label"] = o.label;
        prov["accuracy"] = accuracy;
        prov["commit"] = commit + (dirty ? "-dirty" : "");
        prov["date"] = utc_now_iso();
        prov["cpu_features"] = cpu_features();
        prov["command"] = bless_command(tc) + (o.label.empty() ? "" : " --label " + o.label);
        fmt::print("{:<9} {}  ({})\n", o.dry_run ? "would" : "blessed", tc.name, change);
        if (!o.dry_run) GoldenStore::write_golden(path, rr.image, prov);
    }
    return failed ? kExitError : kExitPass;
}

} // namespace iblcheck
