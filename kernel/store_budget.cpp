#include "kernel/store_budget.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <tuple>

#include "kernel/errors.h"

namespace fs = std::filesystem;

namespace iblcheck {

std::uintmax_t store_budget_bytes() {
    const char* v = std::getenv("IBLCHECK_CACHE_MAX_MB");
    if (!v || !*v) return kDefaultStoreBudgetMiB << 20;
    const std::string s = v;
    constexpr std::uintmax_t kMaxMiB = std::numeric_limits<std::uintmax_t>::max() >> 20;
    std::uintmax_t mib = 0;
    bool ok = s.size() <= 15 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (ok) {
        mib = std::stoull(s);
        ok = mib >= 1 && mib <= kMaxMiB;
    }
    if (!ok)
        throw UsageError("IBLCHECK_CACHE_MAX_MB='" + s +
                         "': the stores' size budget must be a whole number of MiB from 1 (unset: " +
                         std::to_string(kDefaultStoreBudgetMiB) + ")");
    return mib << 20;
}

bool is_store_entry_name(const std::string& name, const std::string& suffix) {
    if (suffix.empty() || name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
        return false;
    return std::all_of(name.begin(), name.end() - std::ptrdiff_t(suffix.size()),
                       [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

namespace {

struct Entry {
    fs::file_time_type used;
    std::uintmax_t bytes;
    fs::path path;
};

std::vector<Entry> list_entries(const std::vector<StoreFolder>& folders) {
    std::vector<Entry> out;
    for (const StoreFolder& f : folders) {
        if (f.dir.empty()) continue;
        std::error_code ec;
        fs::directory_iterator it(f.dir, ec), end;
        for (; !ec && it != end; it.increment(ec)) {
            if (!is_store_entry_name(it->path().filename().string(), f.suffix)) continue;
            std::error_code e1, e2, e3;
            if (!it->is_regular_file(e1)) continue;
            const std::uintmax_t bytes = it->file_size(e2);
            const fs::file_time_type used = it->last_write_time(e3);
            if (e1 || e2 || e3) continue; // removed by another process meanwhile
            out.push_back({used, bytes, it->path()});
        }
    }
    return out;
}

StoreUsage usage_of(const std::vector<Entry>& entries) {
    StoreUsage u;
    for (const Entry& e : entries) ++u.entries, u.bytes += e.bytes;
    return u;
}

} // namespace

StoreUsage store_usage(const std::vector<StoreFolder>& folders) { return usage_of(list_entries(folders)); }

PruneOutcome prune_stores(const std::vector<StoreFolder>& folders, std::uintmax_t budget, fs::file_time_type keep_since) {
    std::vector<Entry> entries = list_entries(folders);
    PruneOutcome o;
    o.before = o.after = usage_of(entries);
    if (o.before.bytes <= budget) return o;
    // Oldest use first; the path breaks ties so that the order does not depend on the folder's.
    std::sort(entries.begin(), entries.end(),
              [](const Entry& a, const Entry& b) { return std::tie(a.used, a.path) < std::tie(b.used, b.path); });
    for (const Entry& e : entries) {
        if (o.after.bytes <= budget || e.used >= keep_since) break;
        std::error_code ec;
        if (!fs::remove(e.path, ec) || ec) continue; // gone already, or not ours to remove
        --o.after.entries, o.after.bytes -= e.bytes;
        ++o.removed, o.removed_bytes += e.bytes;
    }
    return o;
}

} // namespace iblcheck
