#include "results/results.h"

#include <fmt/core.h>

#include <cmath>

#include "kernel/errors.h"
#include "metrics/catalog.h"

using nlohmann::json;

namespace iblcheck {

namespace {

json optional_number(const std::optional<double>& v) { return v ? json(*v) : json(); }
// JSON has no NaN or infinity: they are written as null, and null reads back as NaN.
json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(); }
double number_or_nan(const json& j, const char* key) {
    auto it = j.find(key);
    return it != j.end() && it->is_number() ? it->get<double>() : std::nan("");
}
std::optional<double> optional_number_of(const json& j, const char* key) {
    auto it = j.find(key);
    return it != j.end() && it->is_number() ? std::optional<double>(it->get<double>()) : std::nullopt;
}
std::string string_of(const json& j, const char* key) {
    auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}
json json_of(const json& j, const char* key) { return j.value(key, json()); }
template <class T> std::optional<T> optional_of(const json& j, const char* key) {
    auto it = j.find(key);
    return it != j.end() && !it->is_null() ? std::optional<T>(it->get<T>()) : std::nullopt;
}

json to_json(const WorstBlock& b) {
    const auto& [x, y, flip, metric, sphere] = b; // every member: a new one must be written here
    return {{"x", x}, {"y", y}, {"flip", flip}, {"metric", metric}, {"sphere", sphere}};
}
WorstBlock worst_block_from_json(const json& j) {
    return {j.value("x", 0), j.value("y", 0), number_or_nan(j, "flip"), string_of(j, "metric"), string_of(j, "sphere")};
}

json to_json(const Timing& t) { return {{"pass", t.pass}, {"ms", t.ms}, {"gpu", t.gpu}, {"precompute", t.precompute}}; }

// A figure's name in the accuracy summary: the metric catalog's (metrics/catalog.h, accuracy_name).
namespace {
const char* summary_name(const char* metric_key) { return metric(metric_key).accuracy_name; }
} // namespace

json to_json(const Accuracy& a) {
    const auto& [flip_mean, ssim, golden, noise_floor, display] = a; // every member
    // SSIM of an image smaller than its window is NaN here, null in the JSON.
    json j = {{summary_name("flip.mean"), flip_mean},
              {summary_name("ssim.mean"), finite_or_null(ssim)},
              {"golden", golden},
              {"noise_floor", noise_floor}};
    if (display)
        j["display"] = {{"space", display->space},
                        {summary_name("display_flip.mean"), finite_or_null(display->flip_mean)},
                        {summary_name("display_ssim.mean"), finite_or_null(display->ssim)},
                        {summary_name("display_psnr.db"), finite_or_null(display->psnr_db)}};
    return j;
}
Accuracy accuracy_from_json(const json& j) {
    Accuracy a{number_or_nan(j, summary_name("flip.mean")),
               number_or_nan(j, summary_name("ssim.mean")),
               string_of(j, "golden"),
               json_of(j, "noise_floor"),
               {}};
    if (const json d = json_of(j, "display"); d.is_object())
        a.display = DisplayAccuracy{json_of(d, "space"), number_or_nan(d, summary_name("display_flip.mean")),
                                    number_or_nan(d, summary_name("display_ssim.mean")),
                                    number_or_nan(d, summary_name("display_psnr.db"))};
    return a;
}

// The render's figures, flat in the test object.
void write_render(json& j, const RenderFigures& r) {
    const auto& [width, height, timings, precompute_ms, frame_ms, frame_ms_samples, timing_group, texture_fetches_per_pixel,
                 texture_bytes, texel_count, cost, provenance] = r; // every member: a new one must be written here
    j["width"] = width;
    j["height"] = height;
    j["timings"] = json::array();
    for (const Timing& t : timings) j["timings"].push_back(to_json(t));
    j["precompute_ms"] = precompute_ms;
    j["frame_ms"] = frame_ms;
    if (!frame_ms_samples.empty()) j["frame_ms_samples"] = frame_ms_samples;
    if (!timing_group.empty()) j["timing_group"] = timing_group;
    j["texture_fetches_per_pixel"] = texture_fetches_per_pixel;
    if (texture_bytes) j["texture_bytes"] = *texture_bytes;
    if (texel_count) j["texel_count"] = *texel_count;
    j["cost"] = cost;
    j["provenance"] = provenance;
}
std::optional<RenderFigures> render_from_json(const json& j) {
    if (!j.contains("width")) return std::nullopt;
    RenderFigures r;
    r.width = j.value("width", 0);
    r.height = j.value("height", 0);
    for (const json& t : j.value("timings", json::array()))
        r.timings.push_back({string_of(t, "pass"), number_or_nan(t, "ms"), t.value("gpu", false), t.value("precompute", false)});
    r.precompute_ms = number_or_nan(j, "precompute_ms");
    r.frame_ms = number_or_nan(j, "frame_ms");
    r.frame_ms_samples = j.value("frame_ms_samples", std::vector<double>{});
    r.timing_group = j.value("timing_group", std::string());
    r.texture_fetches_per_pixel = number_or_nan(j, "texture_fetches_per_pixel");
    r.texture_bytes = optional_of<uint64_t>(j, "texture_bytes");
    r.texel_count = optional_of<uint64_t>(j, "texel_count");
    r.cost = json_of(j, "cost");
    r.provenance = json_of(j, "provenance");
    return r;
}

} // namespace

std::string_view verdict_name(Verdict v) {
    switch (v) {
    case Verdict::pass: return "pass";
    case Verdict::improved: return "improved";
    case Verdict::fail: return "fail";
    case Verdict::missing_golden: return "missing-golden";
    case Verdict::error: return "error";
    }
    return "error";
}

Verdict parse_verdict(std::string_view name) {
    for (Verdict v : {Verdict::pass, Verdict::improved, Verdict::fail, Verdict::missing_golden, Verdict::error})
        if (verdict_name(v) == name) return v;
    throw InputError(fmt::format("unknown verdict '{}'", name));
}

json to_json(const Check& c) {
    const auto& [metric, value, min, max, approved, status, message] = c; // every member: a new one must be written here
    json j = {{"metric", metric},
              {"value", finite_or_null(value)},
              {"min", optional_number(min)},
              {"max", optional_number(max)},
              {"status", verdict_name(status)}};
    if (approved) j["approved"] = finite_or_null(*approved);
    if (!message.empty()) j["message"] = message;
    return j;
}

json to_json(const Comparison& c) {
    const auto& [kind, golden, label, metrics, checks, verdict, message, images, worst_block, approved] = c; // every member
    json j = {{"kind", kind}, {"golden", golden}, {"verdict", verdict_name(verdict)}};
    if (kind == "baseline") j["label"] = label;
    if (!metrics.is_null()) j["metrics"] = metrics;
    j["checks"] = json::array();
    for (const Check& k : checks) j["checks"].push_back(to_json(k));
    if (!message.empty()) j["message"] = message;
    if (!images.is_null()) j["images"] = images;
    if (worst_block) j["worst_block"] = to_json(*worst_block);
    if (!approved.is_null()) j["approved"] = approved;
    return j;
}

json to_json(const TestResult& t) {
    const auto& [name, suite, scene, method, env, options, variant, display, tags, bless_command, render, image, image_exr,
                 layout, comparisons, accuracy, driver_mismatch, per_sphere, furnace, temporal, stability, verdict, message,
                 wall_s,
                 profile] = t; // every member: a new one must be written here, in fields() and in RESULTS_FORMAT.md
    json j = {
        {"name", name},       {"suite", suite},     {"scene", scene},     {"method", method}, {"env", env},
        {"options", options}, {"variant", variant}, {"display", display}, {"tags", tags},     {"bless_command", bless_command}};
    if (render) write_render(j, *render);
    if (image) j["image"] = *image;
    if (image_exr) j["image_exr"] = *image_exr;
    if (layout) j["layout"] = *layout;
    j["comparisons"] = json::array();
    for (const Comparison& c : comparisons) j["comparisons"].push_back(to_json(c));
    j["accuracy"] = accuracy ? to_json(*accuracy) : json();
    j["driver_mismatch"] = driver_mismatch ? json(*driver_mismatch) : json();
    if (!per_sphere.is_null()) j["per_sphere"] = per_sphere;
    if (furnace) j["furnace"] = *furnace;
    if (temporal) j["temporal"] = *temporal;
    if (stability) j["stability"] = *stability;
    j["verdict"] = verdict_name(verdict);
    j["message"] = message;
    if (wall_s) j["wall_s"] = *wall_s;
    if (profile) j["profile"] = *profile;
    return j;
}

json count_verdicts(const std::vector<TestResult>& tests) {
    json counts = json::object();
    for (Verdict v : {Verdict::pass, Verdict::fail, Verdict::improved, Verdict::missing_golden, Verdict::error})
        counts[std::string(verdict_name(v))] = 0;
    for (const TestResult& t : tests) {
        json& n = counts[std::string(verdict_name(t.verdict))];
        n = n.get<int>() + 1;
    }
    return counts;
}

json to_json(const RunResults& r) {
    const auto& [suite, command, started, total_s, commit, dirty, driver, cpu_features, cpu_class, shard, tests] =
        r; // every member
    json j = {{"schema", kResultsSchema}, {"suite", suite}, {"command", command}, {"started", started}};
    j["total_s"] = total_s;
    j["dirty"] = dirty;
    j["commit"] = commit;
    j["driver"] = driver;
    j["cpu_features"] = cpu_features;
    j["cpu_class"] = cpu_class;
    j["shard"] = shard;
    j["tests"] = json::array();
    for (const TestResult& t : tests) j["tests"].push_back(to_json(t));
    j["counts"] = count_verdicts(tests);
    return j;
}

void from_json(const json& j, Check& c) {
    c.metric = string_of(j, "metric");
    c.value = number_or_nan(j, "value");
    c.min = optional_number_of(j, "min");
    c.max = optional_number_of(j, "max");
    if (j.contains("approved")) c.approved = number_or_nan(j, "approved");
    c.status = parse_verdict(string_of(j, "status"));
    c.message = string_of(j, "message");
}

void from_json(const json& j, Comparison& c) {
    c.kind = string_of(j, "kind");
    c.golden = string_of(j, "golden");
    c.label = string_of(j, "label");
    c.metrics = json_of(j, "metrics");
    c.checks = j.value("checks", std::vector<Check>{});
    c.verdict = parse_verdict(j.value("verdict", "pass"));
    c.message = string_of(j, "message");
    c.images = json_of(j, "images");
    if (const json b = json_of(j, "worst_block"); b.is_object()) c.worst_block = worst_block_from_json(b);
    c.approved = json_of(j, "approved");
}

void from_json(const json& j, TestResult& t) {
    for (auto [field, key] : {std::pair{&t.name, "name"},
                              {&t.suite, "suite"},
                              {&t.scene, "scene"},
                              {&t.method, "method"},
                              {&t.env, "env"},
                              {&t.variant, "variant"},
                              {&t.bless_command, "bless_command"},
                              {&t.message, "message"}})
        *field = string_of(j, key);
    t.options = json_of(j, "options");
    t.display = json_of(j, "display");
    t.tags = j.value("tags", std::vector<std::string>{});
    t.render = render_from_json(j);
    t.image = optional_of<std::string>(j, "image");
    t.image_exr = optional_of<std::string>(j, "image_exr");
    if (j.contains("layout")) t.layout = j["layout"]; // null too: the render had more spheres than an id map holds
    t.comparisons = j.value("comparisons", std::vector<Comparison>{});
    if (const json a = json_of(j, "accuracy"); a.is_object()) t.accuracy = accuracy_from_json(a);
    t.driver_mismatch = optional_of<std::string>(j, "driver_mismatch");
    t.per_sphere = json_of(j, "per_sphere");
    for (auto [field, key] : {std::pair{&t.furnace, "furnace"}, {&t.temporal, "temporal"}, {&t.stability, "stability"}})
        if (j.contains(key)) *field = j[key];
    t.verdict = parse_verdict(string_of(j, "verdict"));
    t.wall_s = optional_number_of(j, "wall_s");
    t.profile = optional_of<json>(j, "profile");
}

void from_json(const json& j, RunResults& r) {
    for (auto [field, key] : {std::pair{&r.suite, "suite"},
                              {&r.command, "command"},
                              {&r.started, "started"},
                              {&r.commit, "commit"},
                              {&r.cpu_class, "cpu_class"},
                              {&r.shard, "shard"}})
        *field = string_of(j, key);
    r.total_s = number_or_nan(j, "total_s");
    r.dirty = j.value("dirty", false);
    r.driver = json_of(j, "driver");
    r.cpu_features = json_of(j, "cpu_features");
    r.tests = j.value("tests", std::vector<TestResult>{});
}

const std::vector<Field>& fields(ResultsObject object) {
    using T = JsonType;
    static const std::vector<Field> run = {{"schema", T::string, true, true},
                                           {"tests", T::array, true, true},
                                           {"suite", T::string, false, true},
                                           {"command", T::string, false, true},
                                           {"started", T::string, false, true},
                                           {"total_s", T::number, false, true},
                                           {"commit", T::string, false, true},
                                           {"dirty", T::boolean, false, true},
                                           {"driver", T::object, false, true},
                                           {"counts", T::object, false, true},
                                           {"cpu_features", T::array},
                                           {"cpu_class", T::string},
                                           {"shard", T::string},
                                           {"shards", T::array}};
    static const std::vector<Field> test = {{"name", T::string, true, true},
                                            {"verdict", T::string, true, true},
                                            {"suite", T::string, false, true},
                                            {"scene", T::string, false, true},
                                            {"method", T::string, false, true},
                                            {"env", T::string, false, true},
                                            {"variant", T::string, false, true},
                                            {"options", T::object, false, true},
                                            {"width", T::number, false, true},
                                            {"height", T::number, false, true},
                                            {"message", T::string, false, true},
                                            {"bless_command", T::string, false, true},
                                            {"driver_mismatch", T::string, false, true},
                                            {"image", T::string, false, true},
                                            {"image_exr", T::string, false, true},
                                            {"layout", T::object, false, true},
                                            {"comparisons", T::array, false, true},
                                            {"timings", T::array, false, true},
                                            {"precompute_ms", T::number, false, true},
                                            {"frame_ms", T::number, false, true},
                                            {"frame_ms_samples", T::array, false, true},
                                            {"timing_group", T::string, false, true},
                                            {"profile", T::object},
                                            {"texture_fetches_per_pixel", T::number, false, true},
                                            {"texture_bytes", T::number, false, true},
                                            {"texel_count", T::number, false, true},
                                            {"cost", T::object, false, true},
                                            {"display", T::object},
                                            {"accuracy", T::object, false, true},
                                            {"per_sphere", T::array, false, true},
                                            {"furnace", T::object},
                                            {"temporal", T::object, false, true},
                                            {"stability", T::object, false, true},
                                            {"tags", T::array},
                                            {"provenance", T::object},
                                            {"wall_s", T::number}};
    static const std::vector<Field> comparison = {{"kind", T::string, true, true},         {"golden", T::string, false, true},
                                                  {"label", T::string, false, true},       {"message", T::string, false, true},
                                                  {"verdict", T::string, false, true},     {"metrics", T::object, false, true},
                                                  {"checks", T::array, false, true},       {"images", T::object, false, true},
                                                  {"worst_block", T::object, false, true}, {"approved", T::object, false, true}};
    static const std::vector<Field> check = {{"metric", T::string, true, true},
                                             {"value", T::number, false, true},
                                             {"min", T::number, false, true},
                                             {"max", T::number, false, true},
                                             {"status", T::string, false, true},
                                             {"approved", T::number, false, true},
                                             {"message", T::string}};
    switch (object) {
    case ResultsObject::run: return run;
    case ResultsObject::test: return test;
    case ResultsObject::comparison: return comparison;
    case ResultsObject::check: return check;
    }
    return run;
}

} // namespace iblcheck
