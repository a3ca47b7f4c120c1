// `--filter` on test names (run, bless, bisect; suite.h glob_match): globs with * and ? (fnmatch on
// the whole name, '\' escapes) separated by '|'. A name is selected when one glob matches it and
// no glob written `!GLOB` does (issue 32: the approve command of 52 failures of one cause is
// `mobile.*|!*mip_mapping=*|!mobile.furnace.*`, not 52 names). Only `!` globs: every other name.
// Header-only so the report (failure_groups.cpp) checks its filters with the harness's own rule.
#pragma once
#include <fnmatch.h>

#include <string>

namespace iblcheck {

inline bool name_filter_match(const std::string& filter, const std::string& name) {
    if (filter.empty()) return true;
    bool positive = false, any_positive = false;
    std::string one;
    for (size_t i = 0; i <= filter.size(); ++i) {
        if (i == filter.size() || filter[i] == '|') {
            const bool negative = !one.empty() && one[0] == '!';
            const std::string glob = negative ? one.substr(1) : one;
            const bool hit = ::fnmatch(glob.c_str(), name.c_str(), 0) == 0;
            if (negative && hit) return false;
            if (!negative) any_positive = true, positive = positive || hit;
            one.clear();
            continue;
        }
        one += filter[i];
        if (filter[i] == '\\' && i + 1 < filter.size()) one += filter[++i];
    }
    return positive || !any_positive;
}

} // namespace iblcheck
