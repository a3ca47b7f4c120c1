// Validation of the results JSON (schema iblcheck-results/1, results/RESULTS_FORMAT.md). Only the
// keys the report needs are required; every other key it reads is checked for its type when
// present, so a harness bug is reported as "<file>: tests[3] (name): 'frame_ms' must be a number",
// not a crash. The keys and their types are the typed results' (results.h: fields()); here, what
// lies inside them.
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "kernel/json_check.h"
#include "metrics/catalog.h"
#include "results/results.h"
#include "results/results_file.h"

namespace iblcheck::results {

namespace {

using json = nlohmann::json;

// The results reader's checks: keys of objects, by type (kernel/json_check.h), and the
// arrays and maps of one type the results hold.
struct Checker : JsonChecker {
    using JsonChecker::JsonChecker;

    const json& require(const json& obj, const std::string& where, const char* key) const {
        auto it = obj.find(key);
        if (it == obj.end()) fail(where, fmt::format("missing key '{}'", key));
        return *it;
    }
    void string_(const json& obj, const std::string& where, const char* key, bool required = false) const {
        member(obj, where, key, JsonType::string, required);
    }
    void number(const json& obj, const std::string& where, const char* key, bool required = false) const {
        member(obj, where, key, JsonType::number, required);
    }
    void boolean(const json& obj, const std::string& where, const char* key) const { member(obj, where, key, JsonType::boolean); }
    // Return nullptr when absent or null.
    const json* object(const json& obj, const std::string& where, const char* key) const {
        return member(obj, where, key, JsonType::object);
    }
    const json* array(const json& obj, const std::string& where, const char* key) const {
        return member(obj, where, key, JsonType::array);
    }
    void string_array(const json& obj, const std::string& where, const char* key) const {
        if (const json* a = array(obj, where, key))
            for (size_t i = 0; i < a->size(); ++i)
                if (!(*a)[i].is_string())
                    fail(where, fmt::format("'{}[{}]' must be a string (an image path), not {}", key, i, (*a)[i].type_name()));
    }
    void number_map(const json& obj, const std::string& where, const char* key) const {
        if (const json* m = object(obj, where, key))
            for (auto& [k, v] : m->items())
                if (!v.is_number() && !v.is_null())
                    fail(where, fmt::format("'{}.{}' must be a number, not {}", key, k, v.type_name()));
    }
};

const std::set<std::string>& verdicts() {
    static const std::set<std::string> v{"pass", "fail", "improved", "missing-golden", "error"};
    return v;
}

// The keys of one results object the reader checks, each by the type fields() gives it: a
// present key of another type (null is absent) fails, as does a required one that is missing.
void check_fields(const Checker& c, const json& obj, const std::string& where, ResultsObject object) {
    for (const Field& f : fields(object))
        if (f.checked) c.member(obj, where, f.key, f.type, f.required);
}

// One entry of a test's "comparisons": its kind, metrics, checks, worst block and images.
void check_comparison(const Checker& c, const json& cmp, const std::string& cw) {
    if (!cmp.is_object()) c.fail(cw, fmt::format("must be an object, not {}", cmp.type_name()));
    check_fields(c, cmp, cw, ResultsObject::comparison);
    if (const json* m = c.object(cmp, cw, "metrics"))
        for (auto& [name, group] : m->items()) {
            if (!group.is_object() && !group.is_null())
                c.fail(cw, fmt::format("metrics.{} must be an object, not {}", name, group.type_name()));
        }
    if (const json* checks = c.array(cmp, cw, "checks"))
        for (size_t k = 0; k < checks->size(); ++k) {
            const json& ck = (*checks)[k];
            const std::string kw = fmt::format("{}: checks[{}]", cw, k);
            if (!ck.is_object()) c.fail(kw, fmt::format("must be an object, not {}", ck.type_name()));
            check_fields(c, ck, kw, ResultsObject::check);
        }
    if (const json* wb = c.object(cmp, cw, "worst_block")) {
        for (const char* k : {"x", "y", "flip"}) c.number(*wb, cw + ": worst_block", k);
        c.string_(*wb, cw + ": worst_block", "sphere");
    }
    if (const json* ap = c.object(cmp, cw, "approved"))
        for (auto& [k, v] : ap->items()) {
            if (k == "shader_files" && v.is_object()) { // {file: content hash} (since_baselines.cpp)
                for (auto& [f, h] : v.items())
                    if (!h.is_string())
                        c.fail(cw, fmt::format("approved.shader_files.{} must be a string, not {}", f, h.type_name()));
                continue;
            }
            if (!v.is_string() && !v.is_null()) c.fail(cw, fmt::format("approved.{} must be a string, not {}", k, v.type_name()));
        }
    if (const json* imgs = c.object(cmp, cw, "images"))
        for (auto& [k, v] : imgs->items())
            if (!v.is_string() && !v.is_null())
                c.fail(cw, fmt::format("images.{} must be a string (an image path), not {}", k, v.type_name()));
}

// What a test measured: its pass timings, accuracy, per-sphere errors, temporal and stability figures.
void check_measurements(const Checker& c, const json& t, const std::string& where) {
    if (const json* tim = c.array(t, where, "timings"))
        for (size_t k = 0; k < tim->size(); ++k) {
            const json& p = (*tim)[k];
            const std::string pw = fmt::format("{}: timings[{}]", where, k);
            if (!p.is_object()) c.fail(pw, fmt::format("must be an object, not {}", p.type_name()));
            c.string_(p, pw, "pass", true);
            c.number(p, pw, "ms", true);
            c.boolean(p, pw, "gpu");
            c.boolean(p, pw, "precompute");
        }
    if (const json* acc = c.object(t, where, "accuracy")) {
        c.number(*acc, where + ": accuracy", metric("flip.mean").accuracy_name);
        c.string_(*acc, where + ": accuracy", "golden");
        if (const json* d = c.object(*acc, where + ": accuracy", "display")) // the truth as a player sees it
            c.number(*d, where + ": accuracy.display", metric("display_flip.mean").accuracy_name);
    }
    if (const json* ps = c.array(t, where, "per_sphere"))
        for (size_t k = 0; k < ps->size(); ++k) {
            const json& s = (*ps)[k];
            const std::string sw = fmt::format("{}: per_sphere[{}]", where, k);
            if (!s.is_object()) c.fail(sw, fmt::format("must be an object, not {}", s.type_name()));
            c.string_(s, sw, "label");
            c.number(s, sw, "roughness", true);
            c.number(s, sw, "metallic");
            c.number(s, sw, "flip_mean", true);
        }
    if (const json* tp = c.object(t, where, "temporal")) {
        const std::string tw = where + ": temporal";
        c.string_array(*tp, tw, "frames");
        c.string_array(*tp, tw, "reference_frames");
        for (const char* k : {"flicker", "variation_ratio", "flip_mean"}) c.number(*tp, tw, k);
    }
    if (const json* st = c.object(t, where, "stability")) {
        const std::string sw = where + ": stability";
        c.number_map(*st, sw, "noise_floor");
        c.number_map(*st, sw, "margins");
        c.boolean(*st, sw, "flaky");
    }
}

void check_test(const Checker& c, const json& t, size_t i) {
    std::string where = fmt::format("tests[{}]", i);
    if (!t.is_object()) c.fail(where, fmt::format("must be an object, not {}", t.type_name()));
    c.string_(t, where, "name", true);
    where = fmt::format("tests[{}] ({})", i, t["name"].get<std::string>());
    c.string_(t, where, "verdict", true);
    const std::string verdict = t["verdict"].get<std::string>();
    if (!verdicts().count(verdict))
        c.fail(where, fmt::format("verdict '{}' is not one of pass, fail, improved, missing-golden, error", verdict));
    check_fields(c, t, where, ResultsObject::test);
    c.number_map(t, where, "cost");
    if (const json* smp = c.array(t, where, "frame_ms_samples"))
        for (size_t k = 0; k < smp->size(); ++k)
            if (!(*smp)[k].is_number())
                c.fail(where, fmt::format("'frame_ms_samples[{}]' must be a number, not {}", k, (*smp)[k].type_name()));
    if (const json* lay = c.object(t, where, "layout")) {
        c.string_(*lay, where + ": layout", "id_map");
        if (const json* sp = c.array(*lay, where + ": layout", "spheres"))
            for (size_t k = 0; k < sp->size(); ++k) {
                const std::string sw = fmt::format("{}: layout.spheres[{}]", where, k);
                if (!(*sp)[k].is_object()) c.fail(sw, fmt::format("must be an object, not {}", (*sp)[k].type_name()));
                c.string_((*sp)[k], sw, "label");
                c.number((*sp)[k], sw, "roughness");
                c.number((*sp)[k], sw, "metallic");
            }
    }
    if (const json* o = c.object(t, where, "options"))
        for (auto& [k, v] : o->items())
            if (v.is_object() || v.is_array())
                c.fail(where, fmt::format("options.{} must be a plain value, not {}", k, v.type_name()));

    if (const json* comps = c.array(t, where, "comparisons"))
        for (size_t ci = 0; ci < comps->size(); ++ci)
            check_comparison(c, (*comps)[ci], fmt::format("{}: comparisons[{}]", where, ci));
    check_measurements(c, t, where);
}

} // namespace

void validate_results(const json& r, const std::string& source) {
    Checker c{source};
    if (!r.is_object()) c.fail("", fmt::format("results must be a JSON object, not {}", r.type_name()));
    const json& schema = c.require(r, "", "schema");
    if (!schema.is_string() || schema.get<std::string>() != kResultsSchema)
        c.fail("", fmt::format("schema is {} but this report reads \"iblcheck-results/1\"", schema.dump()));
    const json* tests = c.array(r, "", "tests");
    if (!tests) c.fail("", "missing key 'tests' (an array)");
    check_fields(c, r, "", ResultsObject::run); // driver: its plain values are shown
    c.number_map(r, "", "counts");
    for (size_t i = 0; i < tests->size(); ++i) check_test(c, (*tests)[i], i);
}

json read_results(const std::filesystem::path& file) {
    std::ifstream in = open_input_file(file.string());
    std::stringstream ss;
    ss << in.rdbuf();
    json j;
    try {
        j = json::parse(ss.str());
    } catch (const json::exception& e) { // also numbers out of range (1e400)
        throw InputError(fmt::format("{}: not valid JSON: {}", file.string(), e.what()));
    }
    validate_results(j, file.string());
    return j;
}

} // namespace iblcheck::results
