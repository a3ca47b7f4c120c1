#include "reports/merge_shards.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <regex>
#include <set>

#include "kernel/errors.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck::report {

namespace {

std::string text(const json& r, const char* key) { return r.contains(key) ? r[key].dump() : std::string("(none)"); }

// The field every shard must share: refused naming the first shard that differs, and the field.
void check_same(const std::vector<Shard>& shards, const char* field, const char* what) {
    for (const Shard& s : shards)
        if (text(s.results, field) != text(shards[0].results, field))
            throw InputError(fmt::format(
                "{} and {}: shards of different {} (field \"{}\": {} and {}); merge the shards of one run",
                shards[0].file.string(), s.file.string(), what, field, text(shards[0].results, field), text(s.results, field)));
}

// "i/n" of a shard; InputError naming the file when it is not one.
std::pair<int, int> shard_of(const Shard& s) {
    int i = -1, n = 0;
    char rest = 0;
    const std::string v = s.results.value("shard", "");
    if (std::sscanf(v.c_str(), "%d/%d%c", &i, &n, &rest) != 2 || n < 1 || i < 0 || i >= n)
        throw InputError(fmt::format("{}: field \"shard\" is {}, not INDEX/COUNT as `iblcheck run --shard` writes it",
                                     s.file.string(), text(s.results, "shard")));
    return {i, n};
}

// The shards by index: each of 0..n-1 exactly once (n the count they all give).
std::vector<const Shard*> order_shards(const std::vector<Shard>& shards) {
    const int n = shard_of(shards[0]).second;
    std::vector<const Shard*> by_index(size_t(n), nullptr);
    for (const Shard& s : shards) {
        const auto [i, count] = shard_of(s);
        if (count != n)
            throw InputError(fmt::format("{} and {}: field \"shard\" gives {} and {} shards; merge the shards of one run",
                                         shards[0].file.string(), s.file.string(), n, count));
        if (by_index[size_t(i)])
            throw InputError(fmt::format("{} and {}: both are shard {}/{} (field \"shard\"): overlapping shards",
                                         by_index[size_t(i)]->file.string(), s.file.string(), i, n));
        by_index[size_t(i)] = &s;
    }
    std::string missing;
    for (int i = 0; i < n; ++i)
        if (!by_index[size_t(i)]) missing += (missing.empty() ? "" : ", ") + fmt::format("{}/{}", i, n);
    if (!missing.empty())
        throw InputError(fmt::format("shard(s) {} missing (field \"shard\" of the {} file(s) given, from {}); a merged "
                                     "report of part of a suite would look like all of it",
                                     missing, shards.size(), shards[0].file.string()));
    return by_index;
}

// The tests in suite order: position j·n + k is shard k's j-th test. A test in two shards is refused.
json interleave(const std::vector<const Shard*>& by_index) {
    json tests = json::array();
    std::map<std::string, std::string> seen; // test name -> file
    for (size_t j = 0;; ++j) {
        bool any = false;
        for (const Shard* s : by_index) {
            const json& t = s->results["tests"];
            if (j >= t.size()) continue;
            any = true;
            const std::string name = t[j].value("name", "");
            if (auto [it, fresh] = seen.emplace(name, s->file.string()); !fresh)
                throw InputError(fmt::format("{} and {}: both hold test {} (field \"tests\"): overlapping shards", it->second,
                                             s->file.string(), name));
            tests.push_back(t[j]);
        }
        if (!any) return tests;
    }
}

json count_verdicts(const json& tests) {
    json counts = {{"pass", 0}, {"fail", 0}, {"improved", 0}, {"missing-golden", 0}, {"error", 0}};
    for (const json& t : tests) {
        const std::string v = t.value("verdict", "error");
        counts[counts.contains(v) ? v : "error"] = counts[counts.contains(v) ? v : "error"].get<int>() + 1;
    }
    return counts;
}

} // namespace

json merge_shards(const std::vector<Shard>& shards) {
    if (shards.empty()) throw UsageError("report: no results file given");
    check_same(shards, "suite", "suites");
    check_same(shards, "commit", "commits");
    check_same(shards, "dirty", "working trees (one dirty, one not)");
    check_same(shards, "schema", "schemas");
    const std::vector<const Shard*> by_index = order_shards(shards);
    json merged = by_index[0]->results;
    merged["tests"] = interleave(by_index);
    merged["counts"] = count_verdicts(merged["tests"]);
    merged["shard"] = "0/1";
    merged["command"] = std::regex_replace(merged.value("command", ""), std::regex(" --shard [^ ]+"), "");
    double total = 0;
    std::string started = merged.value("started", "");
    json parts = json::array();
    for (const Shard* s : by_index) {
        total = std::max(total, s->results.value("total_s", 0.0));
        started = std::min(started, s->results.value("started", started));
        parts.push_back({{"file", s->file.string()},
                         {"shard", s->results["shard"]},
                         {"started", s->results.value("started", "")},
                         {"total_s", s->results.value("total_s", 0.0)},
                         {"tests", s->results["tests"].size()}});
    }
    merged["total_s"] = total;
    merged["started"] = started;
    merged["shards"] = parts;
    return merged;
}

} // namespace iblcheck::report
