#include "stability.h"

#include <fmt/core.h>

#include <cmath>
#include <limits>

#include "child_render.h"
#include "metrics/catalog.h"
#include "metrics/identical.h"
#include "metrics/image_compare.h"
#include "renderers/option_table.h"
#include "verdict.h"

using nlohmann::json;

namespace iblcheck {

namespace {
// The metrics whose noise floors are measured (the catalog's noise_floor); with `display`, a display
// test's display figures too (issue 29), so its display tolerances get margins like the linear ones.
std::vector<const MetricInfo*> floor_metrics(bool display) {
    std::vector<const MetricInfo*> m;
    for (const MetricInfo* k : judged_metrics(display))
        if (k->noise_floor) m.push_back(k);
    return m;
}
std::vector<std::string> floor_metrics(const TestCase& tc) {
    std::vector<std::string> keys;
    for (const MetricInfo* k : floor_metrics(tc.display.has_value())) keys.emplace_back(k->key);
    return keys;
}
const DisplaySpace* display_of(const TestCase& tc) { return tc.display ? &*tc.display : nullptr; }

bool monte_carlo(const TestSpec& spec) { return spec.method == "sampled" || spec.method == "reference"; }
bool on_vulkan(const TestSpec& spec) { return spec.method != "reference"; }

// 1. Determinism: repeats in this instance; one lavapipe thread (child process) or threads=1 (CPU).
std::string nondeterminism(const TestCase& tc, Worker& w, const cv::Mat& base) {
    const StabilitySpec& st = tc.stability;
    std::string how;
    auto add = [&](const std::string& s) { how += (how.empty() ? "" : "; ") + s; };
    for (int k = 1; k < st.repeats; ++k)
        if (!bit_identical(w.renderer.render(tc.spec).image, base)) add(fmt::format("repeat {} differs", k));
    if (st.thread_counts && on_vulkan(tc.spec) &&
        !bit_identical(render_in_child(tc.spec, {{"LP_NUM_THREADS", "1"}}, w.device).image, base))
        add("LP_NUM_THREADS=1 differs");
    if (!on_vulkan(tc.spec)) {
        TestSpec one = tc.spec;
        one.options.set("threads", "1");
        if (!bit_identical(w.renderer.render(one).image, base)) add("threads=1 differs");
    }
    return how;
}

// Margins: tolerance width / noise floor (null when the floor is 0: nothing measured moves it).
json margins_of(const TestCase& tc, const std::map<std::string, double>& floor, const json& approved_accuracy) {
    json margins = json::object();
    auto margin = [&](const std::string& name, double width) {
        auto it = floor.find(name);
        if (it == floor.end()) return;
        margins[name] = it->second > 0 ? json(width / it->second) : json();
    };
    for (auto& [metric, bound] : tc.baseline_tolerances) {
        if (bound.max)
            margin(metric, *bound.max);
        else if (bound.min) // a bound on a higher-is-better figure: its distance from a perfect score
            margin(metric, floor_distance(iblcheck::metric(metric), *bound.min));
    }
    for (auto& [metric, band] : tc.reference_band) {
        if (!approved_accuracy.is_object() || !approved_accuracy.contains(metric)) continue;
        double a = approved_accuracy[metric].get<double>();
        margin("accuracy." + metric, std::min(a * band.below, a * band.above) + band.abs);
    }
    return margins;
}
// How far the metrics move under a small camera shift and a small roughness change.
json sensitivity(const TestCase& tc, Worker& w, const cv::Mat& base, int flip_threads) {
    const StabilitySpec& st = tc.stability;
    json sens;
    for (auto [key, value] :
         {std::pair<std::string, std::string>{"camera_shift", fmt::format("{},{},0", st.camera_shift, st.camera_shift)},
          std::pair<std::string, std::string>{"roughness_bias", fmt::format("{}", st.roughness_bias)}}) {
        TestSpec p = tc.spec;
        p.options.set(key, value);
        json m = compare_images(base, w.renderer.render(p).image, flip_threads);
        sens[key] = {{"value", value}};
        for (const MetricInfo* k : floor_metrics(false)) // the linear figures whose floors are measured
            sens[key][k->key] = m[k->group][k->field];
    }
    return sens;
}
} // namespace

double floor_of(const json& metrics, const std::string& metric) {
    return floor_distance(iblcheck::metric(metric), metric_value(metrics, metric));
}

StabilityOutcome run_stability(const TestCase& tc, Worker& w, const cv::Mat& base, const cv::Mat& reference,
                               const json& approved_accuracy, int flip_threads) {
    const StabilitySpec& st = tc.stability;
    StabilityOutcome out;
    json& j = out.json;
    std::string how = nondeterminism(tc, w, base);
    out.deterministic = how.empty();
    j["deterministic"] = out.deterministic;
    if (!out.deterministic) {
        j["nondeterminism"] = how;
        out.problem = "not deterministic: " + how;
    }

    // 2. Noise floors. Variants: other seeds (Monte Carlo) and other CPU classes (Vulkan methods).
    // Against the baseline the variant's difference to this render is the whole floor; against the
    // reference it is how much the accuracy moves.
    std::vector<std::pair<std::string, cv::Mat>> variants;
    if (monte_carlo(tc.spec))
        for (int s = 1; s < st.seeds; ++s) {
            TestSpec seeded = tc.spec;
            seeded.options.set("seed", std::to_string(option_int(tc.spec.options, "seed", tc.spec.method) + s));
            variants.emplace_back(fmt::format("seed {}", s), w.renderer.render(seeded).image);
        }
    json cpu = json::object();
    if (on_vulkan(tc.spec))
        for (const std::string& caps : st.cpu_caps) {
            ChildRender c = render_in_child(tc.spec, {{"GALLIUM_OVERRIDE_CPU_CAPS", caps}}, w.device);
            variants.emplace_back("cpu " + caps, c.image);
        }
    std::map<std::string, double> floor, seed_floor, cpu_floor;
    json m_ref_base = reference.empty() || reference.size() != base.size()
                          ? json()
                          : compare_images(reference, base, flip_threads, nullptr, display_of(tc));
    for (const auto& [name, v] : variants) {
        const bool is_cpu = name.rfind("cpu ", 0) == 0;
        auto& kind_floor = is_cpu ? cpu_floor : seed_floor;
        json m = compare_images(base, v, flip_threads, nullptr, display_of(tc));
        if (is_cpu) {
            json& c = cpu[name.substr(4)];
            for (const std::string& k : floor_metrics(tc)) c[k] = floor_of(m, k);
        }
        for (const std::string& k : floor_metrics(tc)) kind_floor[k] = std::max(kind_floor[k], floor_of(m, k));
        if (!m_ref_base.is_null()) {
            json mr = compare_images(reference, v, flip_threads, nullptr, display_of(tc));
            for (const std::string& k : floor_metrics(tc)) {
                std::string key = "accuracy." + k;
                kind_floor[key] = std::max(kind_floor[key], std::fabs(metric_value(mr, k) - metric_value(m_ref_base, k)));
            }
        }
    }
    for (const auto* f : {&seed_floor, &cpu_floor})
        for (const auto& [k, v] : *f) floor[k] = std::max(floor[k], v);
    j["noise_floor"] = floor;
    j["seed_floor"] = seed_floor;
    j["cpu_floor"] = cpu_floor;
    j["cpu_caps"] = cpu;
    j["seeds"] = monte_carlo(tc.spec) ? st.seeds : 1;

    // 3. Sensitivity: what a quarter-pixel camera shift or a 1e-3 roughness change does.
    j["sensitivity"] = sensitivity(tc, w, base, flip_threads);

    // 4. Margins against the combined floor; the smallest one names the weakest tolerance.
    json margins = margins_of(tc, floor, approved_accuracy);
    j["margins"] = margins;
    j["min_margin"] = st.min_margin;
    std::string which, smallest_metric;
    double smallest = std::numeric_limits<double>::infinity();
    for (auto& [k, v] : margins.items()) {
        if (!v.is_number()) continue;
        double m = v.get<double>();
        if (m < smallest) smallest = m, smallest_metric = k;
        if (m < st.min_margin) which += fmt::format("{} margin {:.2f}; ", k, m);
    }
    j["smallest_margin"] = smallest_metric.empty() ? json() : json{{"metric", smallest_metric}, {"margin", smallest}};
    out.flaky = !which.empty();
    j["flaky"] = out.flaky;
    if (out.flaky) {
        std::string p = fmt::format("flaky: tolerance under {}x its noise floor: {}", st.min_margin, which);
        out.problem += (out.problem.empty() ? "" : "; ") + p;
    }
    return out;
}

} // namespace iblcheck
