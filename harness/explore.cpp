// The option space search of `iblcheck explore` (explore.h).
#include "harness/explore.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "renderers/option_table.h"

namespace iblcheck {

using nlohmann::json;

std::string ExplorePoint::name() const { return options.values().empty() ? "default" : options.canonical(); }

namespace {

// The value the mobile renderer uses for `key` when the configuration does not set it (the option
// table's, as text); a default the renderer computes or that is not a number is no value to start from.
std::string default_value(const std::string& key) {
    const OptionInfo& info = option_info(key);
    const OptionValue& v = option_default(OptionMap{}, key, "mobile");
    if (!info.enumerated() && !std::holds_alternative<int>(v) && !std::holds_alternative<double>(v))
        throw UsageError("--axis " + key + ": the option's default ('" + info.default_text() + "') is not a value to start from");
    return option_value_text(v);
}

std::string current_value(const OptionMap& o, const std::string& key) { return o.get_string(key).value_or(default_value(key)); }

// `o` with key = value, leaving the option unset where the value is its default (one name per point).
OptionMap with(OptionMap o, const std::string& key, const std::string& value) {
    if (value == default_value(key))
        o.erase(key);
    else
        o.set(key, value);
    return o;
}

void check_axes(const std::vector<ExploreAxis>& axes) {
    std::set<std::string> keys;
    for (const ExploreAxis& a : axes) {
        if (a.values.empty()) throw UsageError("--axis " + a.key + ": no values");
        if (!keys.insert(a.key).second) throw UsageError("--axis " + a.key + ": given twice");
        std::set<std::string> vals(a.values.begin(), a.values.end());
        if (vals.size() != a.values.size()) throw UsageError("--axis " + a.key + ": a value is repeated");
        default_value(a.key);
    }
}

} // namespace

ExploreResult explore_descent(const std::vector<ExploreAxis>& axes, const ExploreEvaluate& evaluate, double budget,
                              int max_passes) {
    check_axes(axes);
    ExploreResult r;
    std::map<std::string, size_t> seen; // name -> index in evaluated
    auto eval = [&](const OptionMap& o) -> const ExplorePoint& {
        ExplorePoint probe;
        probe.options = o;
        const std::string key = probe.name();
        if (auto it = seen.find(key); it != seen.end()) return r.evaluated[it->second];
        ExplorePoint p = evaluate(o);
        p.options = o;
        seen[key] = r.evaluated.size();
        r.evaluated.push_back(p);
        return r.evaluated.back();
    };
    r.start = eval(OptionMap{});
    r.ipp_budget = r.start.ipp * (1 + budget);
    r.grid_size = 1;
    for (const ExploreAxis& a : axes) r.grid_size *= double(a.values.size());
    ExplorePoint cur = r.start;
    for (int pass = 1; pass <= max_passes; ++pass) {
        r.passes = pass;
        bool moved = false;
        for (const ExploreAxis& a : axes) {
            const std::string from = current_value(cur.options, a.key);
            ExplorePoint best = cur;
            std::string best_value = from;
            for (const std::string& v : a.values) {
                const ExplorePoint p = eval(with(cur.options, a.key, v)); // a copy: eval may grow the vector
                if (p.ipp <= r.ipp_budget && p.flip < best.flip) best = p, best_value = v;
            }
            if (best_value == from) continue;
            r.moves.push_back({pass, a.key, from, best_value, best.flip, best.ipp});
            cur = best, moved = true;
        }
        if (!moved) break;
    }
    r.best = cur;
    return r;
}

std::vector<size_t> explore_front(const std::vector<ExplorePoint>& points, ExploreCost cost) {
    auto c = [cost](const ExplorePoint& p) {
        return cost == ExploreCost::instructions ? p.ipp : cost == ExploreCost::fetches ? p.fetches : double(p.bytes);
    };
    std::vector<size_t> front;
    for (size_t i = 0; i < points.size(); ++i) {
        bool dominated = false;
        for (size_t j = 0; j < points.size() && !dominated; ++j) {
            const bool no_worse = c(points[j]) <= c(points[i]) && points[j].flip <= points[i].flip;
            const bool better = c(points[j]) < c(points[i]) || points[j].flip < points[i].flip;
            // Equal points: the first rendered stands for both (a front without duplicates).
            dominated = j != i && no_worse && (better || j < i);
        }
        if (!dominated) front.push_back(i);
    }
    std::sort(front.begin(), front.end(), [&](size_t a, size_t b) { return c(points[a]) < c(points[b]); });
    return front;
}

std::vector<ExploreAxis> default_explore_axes() {
    // Every option whose choice the shading or the precompute makes, with the values a mobile title
    // would ship; ssaa 1-2 (4 and up cost 4x the instructions: outside any budget near the default).
    return {{"diffuse", {"sh9", "irradiance_cube"}},
            {"dominant_dir", {"off", "lagarde", "filament"}},
            {"lagarde_roughness", {"alpha", "perceptual"}},
            {"mip_mapping", {"ue4", "filament", "origin"}},
            {"env_brdf", {"approx", "lut"}},
            {"normalization", {"off", "ue4", "directional"}},
            {"specular_aa", {"off", "tokuyoshi"}},
            {"cube_size", {"64", "128", "256"}},
            {"prefilter_samples", {"64", "256", "1024"}},
            {"storage", {"rgba16f", "r11g11b10", "rgbm8"}},
            {"precision", {"highp", "mediump"}},
            {"ssaa", {"1", "2"}}};
}

ExploreAxis parse_explore_axis(const std::string& text) {
    const size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
        throw UsageError("--axis '" + text + "': expected key=value1|value2|...");
    ExploreAxis a{text.substr(0, eq), {}};
    const OptionInfo* info = nullptr;
    for (const OptionInfo& o : option_catalog())
        if (o.key == a.key && o.read_by("mobile")) info = &o;
    if (!info) throw UsageError("--axis " + a.key + ": not an option of the mobile method (iblcheck list)");
    size_t start = eq + 1;
    for (size_t bar; start <= text.size(); start = bar + 1) {
        bar = text.find('|', start);
        if (bar == std::string::npos) bar = text.size();
        const std::string v = text.substr(start, bar - start);
        if (v.empty()) throw UsageError("--axis '" + text + "': an empty value");
        if (info->enumerated()) {
            const auto ch = info->choices();
            if (std::find(ch.begin(), ch.end(), v) == ch.end())
                throw UsageError("--axis " + a.key + ": unknown value '" + v + "'; valid: " + info->values);
        }
        a.values.push_back(v);
    }
    return a;
}

namespace {

json point_json(const ExplorePoint& p) {
    return {{"name", p.name()}, {"options", p.options.values()}, {"flip", p.flip},
            {"ipp", p.ipp},     {"fetches", p.fetches},          {"bytes", p.bytes}};
}

} // namespace

json explore_json(const ExploreResult& r, const std::vector<ExploreAxis>& axes) {
    json j;
    j["start"] = point_json(r.start);
    j["best"] = point_json(r.best);
    j["budget_ipp"] = r.ipp_budget;
    j["passes"] = r.passes;
    j["grid_size"] = r.grid_size;
    j["not_tried"] = r.grid_size - double(r.evaluated.size());
    j["axes"] = json::array();
    for (const ExploreAxis& a : axes) j["axes"].push_back({{"key", a.key}, {"values", a.values}});
    j["evaluated"] = json::array();
    for (const ExplorePoint& p : r.evaluated) j["evaluated"].push_back(point_json(p));
    j["moves"] = json::array();
    for (const ExploreMove& m : r.moves)
        j["moves"].push_back(
            {{"pass", m.pass}, {"key", m.key}, {"from", m.from}, {"to", m.to}, {"flip", m.flip}, {"ipp", m.ipp}});
    for (auto [cost, name] :
         {std::pair{ExploreCost::instructions, "ipp"}, {ExploreCost::fetches, "fetches"}, {ExploreCost::bytes, "bytes"}}) {
        json f = json::array();
        for (size_t i : explore_front(r.evaluated, cost)) f.push_back(r.evaluated[i].name());
        j["front"][name] = f;
    }
    const double gain = r.start.flip > 0 ? 1 - r.best.flip / r.start.flip : 0;
    j["flip_reduction"] = gain;
    j["ipp_ratio"] = r.start.ipp > 0 ? r.best.ipp / r.start.ipp : 0;
    j["target_met"] = gain >= 0.30 && r.best.ipp <= r.start.ipp * 1.10;
    return j;
}

std::string explore_table(const json& j) {
    std::map<std::string, json> by_name;
    for (const json& p : j["evaluated"]) by_name[p["name"].get<std::string>()] = p;
    const json& s = j["start"];
    std::string out =
        fmt::format("default: mean FLIP {:.4f}, {:.0f} instr/px, {:.2f} fetches/px, {} bytes; budget {:.0f} instr/px\n",
                    s["flip"].get<double>(), s["ipp"].get<double>(), s["fetches"].get<double>(), s["bytes"].get<uint64_t>(),
                    j["budget_ipp"].get<double>());
    out += "moves:\n";
    for (const json& m : j["moves"])
        out += fmt::format("  pass {} {} {} -> {}: FLIP {:.4f}, {:.0f} instr/px\n", m["pass"].get<int>(),
                           m["key"].get<std::string>(), m["from"].get<std::string>(), m["to"].get<std::string>(),
                           m["flip"].get<double>(), m["ipp"].get<double>());
    if (j["moves"].empty()) out += "  none: no value of any axis beat the default within the budget\n";
    for (const char* cost : {"ipp", "fetches", "bytes"}) {
        out += fmt::format("Pareto front, mean FLIP against {}:\n", cost);
        for (const json& n : j["front"][cost]) {
            const json& p = by_name[n.get<std::string>()];
            out +=
                fmt::format("  {:8.4f} {:9.0f} instr/px {:6.2f} fetches/px {:10} bytes  {}\n", p["flip"].get<double>(),
                            p["ipp"].get<double>(), p["fetches"].get<double>(), p["bytes"].get<uint64_t>(), n.get<std::string>());
        }
    }
    const json& b = j["best"];
    out += fmt::format(
        "rendered {} of {:.0f} combinations in {} pass(es); not tried: {:.0f} (a coordinate descent: every value of an "
        "axis with the others at the current point)\n",
        j["evaluated"].size(), j["grid_size"].get<double>(), j["passes"].get<int>(), j["not_tried"].get<double>());
    out += fmt::format("best within +10 % instr/px: {} FLIP {:.4f} ({:+.1f} %), {:.0f} instr/px ({:+.1f} %): {}\n",
                       b["name"].get<std::string>(), b["flip"].get<double>(), -100 * j["flip_reduction"].get<double>(),
                       b["ipp"].get<double>(), 100 * (j["ipp_ratio"].get<double>() - 1),
                       j["target_met"].get<bool>() ? "at least 30 % lower: target met" : "less than 30 % lower: target not met");
    return out;
}

} // namespace iblcheck
