#include "timing_groups.h"

#include <fmt/core.h>

#include <algorithm>
#include <map>
#include <tuple>

#include "metrics/display_space.h"

namespace iblcheck {

namespace {

// Members share a group name, their renders and the shader file (the variant names only its stem).
std::string group_key(const TestCase& tc, int suite_repeats) {
    const int r = timing_repeats_of(tc, suite_repeats);
    const std::string g = timing_group(tc, r);
    return g.empty() ? g : fmt::format("{}|{}|{}", g, r, tc.spec.shader);
}

// What makes two renders the same work (timing_groups.h): checked, not assumed.
auto work_of(const RenderFigures& f) { return std::tuple(f.width, f.height, f.texel_count, f.texture_bytes, f.cost.dump()); }

} // namespace

void set_frame_samples(RenderFigures& f, std::vector<double> samples) {
    std::sort(samples.begin(), samples.end());
    const size_t n = samples.size();
    if (n) f.frame_ms = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
    f.frame_ms_samples = std::move(samples);
}

int timing_repeats_of(const TestCase& tc, int suite_repeats) { return tc.timing_repeats ? tc.timing_repeats : suite_repeats; }

std::string timing_group(const TestCase& tc, int repeats) {
    const TestSpec& s = tc.spec;
    if (repeats < 2 || (s.method != "mobile" && s.method != "sampled")) return "";
    // The test's name with its environment as "*": a pattern that matches every member's name.
    std::string g = s.method + "." + s.scene + ".*." + tc.variant;
    if (tc.display) g += ".display=" + display_label(*tc.display);
    if (s.frame) g += fmt::format(".frame={}", s.frame);
    return g;
}

std::vector<int> timing_renders(const std::vector<TestCase>& tests, int suite_repeats) {
    std::map<std::string, int> members;
    for (const TestCase& tc : tests)
        if (std::string g = group_key(tc, suite_repeats); !g.empty()) ++members[g];
    std::vector<int> renders;
    for (const TestCase& tc : tests) {
        const int r = timing_repeats_of(tc, suite_repeats);
        const std::string g = group_key(tc, suite_repeats);
        const int n = g.empty() ? 1 : members[g];
        renders.push_back((r + n - 1) / n);
    }
    return renders;
}

void share_timings(const std::vector<TestCase>& tests, int suite_repeats, std::vector<TestResult>& results) {
    // The members of each group that rendered, in suite order.
    std::map<std::string, std::vector<size_t>> groups;
    for (size_t i = 0; i < tests.size() && i < results.size(); ++i)
        if (std::string g = group_key(tests[i], suite_repeats); !g.empty() && results[i].render) groups[g].push_back(i);
    for (const auto& [key, members] : groups) {
        const auto work = work_of(*results[members.front()].render);
        std::vector<size_t> same;
        for (size_t i : members)
            if (work_of(*results[i].render) == work) same.push_back(i);
        if (same.size() < 2) continue;
        std::vector<double> samples;
        for (size_t i : same) {
            const RenderFigures& f = *results[i].render;
            if (f.frame_ms_samples.empty())
                samples.push_back(f.frame_ms);
            else
                samples.insert(samples.end(), f.frame_ms_samples.begin(), f.frame_ms_samples.end());
        }
        for (size_t i : same) {
            RenderFigures& f = *results[i].render;
            set_frame_samples(f, samples);
            f.timing_group = timing_group(tests[i], timing_repeats_of(tests[i], suite_repeats));
        }
    }
}

} // namespace iblcheck
