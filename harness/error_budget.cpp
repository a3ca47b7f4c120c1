// The error budget ladder (error_budget.h).
#include "harness/error_budget.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "metrics/image_compare.h"
#include "renderers/option_table.h"
#include "renderers/scenes/scene.h"

namespace iblcheck {

using nlohmann::json;

const std::vector<std::pair<std::string, std::string>>& converged_gpu_values() {
    // prefilter_samples 4096: against 2048 it moves the converged rung's mean FLIP against the truth by
    // 0.00017 (0.09 %: 0.18216 and 0.18200 over the whole image, studio sweep, ssaa 8, irradiance cube,
    // rgba32f; the two renders differ by mean FLIP 0.0102).
    static const std::vector<std::pair<std::string, std::string>> v = {
        {"ssaa", "8"},          {"prefilter_samples", "4096"}, {"diffuse", "irradiance_cube"},
        {"env_brdf", "approx"}, {"storage", "rgba32f"},        {"precision", "highp"},
        {"specular_aa", "off"}, {"dominant_dir", "off"},       {"normalization", "off"}};
    return v;
}

namespace {

// The configuration's value of a step's option (the option table's default where not set).
std::string config_value(const OptionMap& o, const std::string& key) {
    if (key == "ssaa") return std::to_string(ssaa_of(o));
    if (key == "prefilter_samples") return std::to_string(option_int(o, key, "mobile"));
    return option_choice(o, key);
}

bool is_scene_key(const std::string& k) {
    const auto& keys = scene_option_keys();
    return k != "ao" && std::find(keys.begin(), keys.end(), k) != keys.end();
}

// The steps to walk: those whose configuration value differs from the converged one, in `order`
// first, then the pipeline order.
std::vector<std::pair<std::string, std::string>> steps(const OptionMap& config, const std::vector<std::string>& order) {
    const auto& conv = converged_gpu_values();
    for (const std::string& k : order)
        if (std::none_of(conv.begin(), conv.end(), [&](const auto& c) { return c.first == k; }))
            throw UsageError("--order: '" + k +
                             "' is not a step of the ladder (ssaa, prefilter_samples, diffuse, env_brdf, "
                             "storage, precision, specular_aa, dominant_dir, normalization)");
    std::vector<std::string> keys = order;
    for (const auto& c : conv)
        if (std::find(keys.begin(), keys.end(), c.first) == keys.end()) keys.push_back(c.first);
    std::vector<std::pair<std::string, std::string>> out;
    for (const std::string& k : keys) {
        const std::string v = config_value(config, k);
        const auto it = std::find_if(conv.begin(), conv.end(), [&](const auto& c) { return c.first == k; });
        if (v != it->second) out.emplace_back(k, v);
    }
    return out;
}

} // namespace

BudgetPlan plan_budget(const std::string& scene, const std::string& env, const OptionMap& config,
                       const std::vector<std::string>& order) {
    OptionMap shared, truth_only, gpu;
    for (const auto& [k, v] : config.values()) {
        if (k == "ao") {
            if (option_double(config, "ao", "mobile") != 1)
                throw UsageError("--set ao=" + v + ": the truth models no ambient occlusion (ao = 1 only)");
        } else if (is_scene_key(k) || k == "env_rotation") {
            shared.set(k, v);
        } else if (k == "truth_tolerance" || k == "threads") {
            truth_only.set(k, v);
        } else if (std::any_of(option_catalog().begin(), option_catalog().end(),
                               [&](const OptionInfo& o) { return o.key == k && o.read_by("mobile"); })) {
            gpu.set(k, v);
        } else {
            throw UsageError("--set " + k + ": not an option of the mobile configuration (iblcheck list)");
        }
    }
    BudgetPlan plan;
    auto spec_of = [&](const std::string& method) {
        TestSpec t;
        t.scene = scene, t.method = method, t.env = env, t.options = shared;
        return t;
    };
    plan.truth = spec_of("reference");
    for (const auto& [k, v] : truth_only.values()) plan.truth.options.set(k, v);
    auto cpu_rung = [&](const std::string& mode, const std::string& label) {
        BudgetRung r{mode == "exact" ? "split_sum" : "env_brdf_approx", label, plan.truth};
        r.spec.options.set("split_sum", mode);
        return r;
    };
    plan.ladder.push_back(cpu_rung("exact", "split sum, exact parts (n = v = R)"));
    plan.ladder.push_back(cpu_rung("env_brdf_approx", "EnvBRDFApprox for the exact DFG"));
    TestSpec converged = spec_of("mobile");
    for (const auto& [k, v] : gpu.values()) converged.options.set(k, v);
    for (const auto& [k, v] : converged_gpu_values()) converged.options.set(k, v);
    plan.ladder.push_back({"mip_chain", "GPU converged: the prefiltered mip chain", converged});
    TestSpec walk = converged;
    for (const auto& [k, v] : steps(config, order)) {
        const std::string from = converged.options.get_string(k).value_or("");
        walk.options.set(k, v);
        const std::string label = fmt::format("{} {} -> {}", k, from, v);
        plan.ladder.push_back({k, label, walk});
        TestSpec alone = converged;
        alone.options.set(k, v);
        plan.isolated.push_back({k, label, alone});
    }
    return plan;
}

RungErrors measure_errors(const cv::Mat& truth, const cv::Mat& test, const SphereCoverage& coverage, int flip_threads) {
    FlipResult flip;
    compare_images(truth, test, flip_threads, &flip);
    const size_t n = coverage.spheres.size();
    struct Sums {
        double d = 0, d2 = 0, r = 0, flip = 0;
        long px = 0;
    };
    std::vector<Sums> s(n + 1); // spheres, then every covered pixel
    for (int y = 0; y < truth.rows; ++y)
        for (int x = 0; x < truth.cols; ++x) {
            const int id = coverage.ids.at<int>(y, x);
            if (id < 0) continue;
            const auto &a = truth.at<cv::Vec3f>(y, x), &b = test.at<cv::Vec3f>(y, x);
            for (Sums* t : {&s[size_t(id)], &s[n]}) {
                for (int q = 0; q < 3; ++q) {
                    const double d = double(b[q]) - a[q];
                    t->d += d, t->d2 += d * d, t->r += a[q];
                }
                t->flip += flip.errmap.at<float>(y, x), ++t->px;
            }
        }
    auto figures = [](const Sums& t) {
        ErrorFigures f;
        if (t.px == 0 || t.r <= 0) return f;
        f.bias = t.d / t.r;
        f.rmse = std::sqrt(t.d2 / (3.0 * double(t.px))) / (t.r / (3.0 * double(t.px)));
        f.flip = t.flip / double(t.px);
        return f;
    };
    RungErrors out;
    for (size_t i = 0; i < n; ++i) out.spheres.push_back(figures(s[i]));
    out.image = figures(s[n]);
    return out;
}

namespace {

json figures_json(const ErrorFigures& f) { return {{"bias", f.bias}, {"rmse", f.rmse}, {"flip", f.flip}}; }
ErrorFigures minus(const ErrorFigures& a, const ErrorFigures& b) { return {a.bias - b.bias, a.rmse - b.rmse, a.flip - b.flip}; }

json errors_json(const RungErrors& e, const SphereCoverage& cov) {
    json spheres = json::array();
    for (size_t i = 0; i < e.spheres.size(); ++i) {
        json s = figures_json(e.spheres[i]);
        s["label"] = cov.spheres[i].label;
        s["roughness"] = cov.spheres[i].roughness;
        s["metallic"] = cov.spheres[i].metallic;
        spheres.push_back(s);
    }
    return {{"image", figures_json(e.image)}, {"spheres", spheres}};
}

RungErrors difference(const RungErrors& a, const RungErrors* b) {
    RungErrors d = a;
    if (!b) return d;
    d.image = minus(a.image, b->image);
    for (size_t i = 0; i < d.spheres.size(); ++i) d.spheres[i] = minus(a.spheres[i], b->spheres[i]);
    return d;
}

void accumulate(RungErrors& sum, const RungErrors& e) {
    auto add = [](ErrorFigures& a, const ErrorFigures& b) { a.bias += b.bias, a.rmse += b.rmse, a.flip += b.flip; };
    add(sum.image, e.image);
    for (size_t i = 0; i < sum.spheres.size(); ++i) add(sum.spheres[i], e.spheres[i]);
}

} // namespace

json budget_json(const BudgetPlan& plan, const std::vector<RungErrors>& ladder, const std::vector<RungErrors>& isolated,
                 const SphereCoverage& cov, const std::vector<RungErrors>& steps) {
    json j;
    j["rungs"] = json::array();
    RungErrors zero = ladder.front();
    zero.image = {};
    for (auto& s : zero.spheres) s = {};
    RungErrors sum_shares = zero, sum_isolated = zero;
    const RungErrors* converged = nullptr;
    for (size_t i = 0; i < plan.ladder.size(); ++i) {
        const BudgetRung& r = plan.ladder[i];
        const RungErrors share = difference(ladder[i], i ? &ladder[i - 1] : nullptr);
        accumulate(sum_shares, share);
        json rung = {{"key", r.key}, {"label", r.label}, {"method", r.spec.method}, {"options", r.spec.options.values()}};
        rung["error"] = errors_json(ladder[i], cov);
        rung["share"] = errors_json(share, cov);
        if (r.key == "mip_chain") converged = &ladder[i];
        // The base rungs' isolated effects are their shares; the GPU steps' are rendered alone.
        const size_t k =
            size_t(std::find_if(plan.isolated.begin(), plan.isolated.end(), [&](const BudgetRung& b) { return b.key == r.key; }) -
                   plan.isolated.begin());
        const RungErrors iso = k < isolated.size() && converged ? difference(isolated[k], converged) : share;
        rung["isolated"] = errors_json(iso, cov);
        if (i < steps.size()) rung["step"] = errors_json(steps[i], cov);
        accumulate(sum_isolated, iso);
        j["rungs"].push_back(rung);
    }
    const RungErrors& total = ladder.back();
    j["total"] = errors_json(total, cov);
    j["sum_of_shares"] = errors_json(sum_shares, cov);
    j["sum_of_isolated"] = errors_json(sum_isolated, cov);
    j["interaction"] = errors_json(difference(total, &sum_isolated), cov);
    return j;
}

std::string budget_table(const json& b) {
    std::string out = fmt::format("{:<44} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}  {}\n", "rung (cumulative)", "FLIP", "share",
                                  "isolated", "step", "bias", "rRMSE", "largest FLIP share (sphere)");
    for (const json& r : b["rungs"]) {
        const json& sp = r["share"]["spheres"];
        size_t worst = 0;
        for (size_t i = 1; i < sp.size(); ++i)
            if (std::fabs(sp[i]["flip"].get<double>()) > std::fabs(sp[worst]["flip"].get<double>())) worst = i;
        const std::string step = r.contains("step") ? fmt::format("{:8.4f}", r["step"]["image"]["flip"].get<double>()) : "-";
        out +=
            fmt::format("{:<44} {:8.4f} {:+8.4f} {:+8.4f} {:>8} {:+8.4f} {:8.4f}  {:+.4f} ({})\n", r["label"].get<std::string>(),
                        r["error"]["image"]["flip"].get<double>(), r["share"]["image"]["flip"].get<double>(),
                        r["isolated"]["image"]["flip"].get<double>(), step, r["error"]["image"]["bias"].get<double>(),
                        r["error"]["image"]["rmse"].get<double>(), sp.empty() ? 0.0 : sp[worst]["flip"].get<double>(),
                        sp.empty() ? "" : sp[worst]["label"].get<std::string>());
    }
    out += fmt::format("{:<44} {:8.4f}   (Σ isolated {:.4f}, interaction {:+.4f})\n", "total",
                       b["total"]["image"]["flip"].get<double>(), b["sum_of_isolated"]["image"]["flip"].get<double>(),
                       b["interaction"]["image"]["flip"].get<double>());
    // Per sphere: the FLIP share of each rung (columns), the total last.
    out += fmt::format("\nmean FLIP share per sphere\n{:<18}", "sphere");
    for (const json& r : b["rungs"]) out += fmt::format(" {:>9.9}", r["key"].get<std::string>());
    out += fmt::format(" {:>9}\n", "total");
    const json& tot = b["total"]["spheres"];
    for (size_t i = 0; i < tot.size(); ++i) {
        out += fmt::format("{:<18}", tot[i]["label"].get<std::string>());
        for (const json& r : b["rungs"]) out += fmt::format(" {:+9.4f}", r["share"]["spheres"][i]["flip"].get<double>());
        out += fmt::format(" {:9.4f}\n", tot[i]["flip"].get<double>());
    }
    return out;
}

} // namespace iblcheck
