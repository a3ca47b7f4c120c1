#include "kernel/output_files.h"

#include "kernel/errors.h"

namespace fs = std::filesystem;

namespace iblcheck {

bool same_file(const fs::path& a, const fs::path& b) {
    if (a.empty() || b.empty()) return false;
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
    const fs::path ca = fs::weakly_canonical(fs::absolute(a), ec), cb = fs::weakly_canonical(fs::absolute(b), ec);
    return ca.lexically_normal() == cb.lexically_normal();
}

void check_output_file(const fs::path& out, const std::string& option, bool force, const std::vector<fs::path>& inputs) {
    if (out.empty()) return;
    for (const fs::path& in : inputs)
        if (same_file(out, in))
            throw UsageError(option + " " + out.string() + ": is also an input (" + in.string() +
                             "); an output never overwrites an input, not even with --force");
    std::error_code ec;
    if (!force && fs::symlink_status(out, ec).type() != fs::file_type::not_found)
        throw UsageError(option + " " + out.string() + ": exists; pass --force to overwrite it");
}

void check_distinct_outputs(const fs::path& a, const std::string& option_a, const fs::path& b, const std::string& option_b) {
    if (same_file(a, b))
        throw UsageError(option_a + " " + a.string() + " and " + option_b + " " + b.string() +
                         ": the same file; give each its own");
}

fs::path inside_folder(const fs::path& dir, const std::string& rel) {
    if (rel.empty()) return {};
    const fs::path p(rel);
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(fs::absolute(dir), ec);
    const fs::path file = fs::weakly_canonical(fs::absolute(p.is_absolute() ? p : dir / p), ec);
    if (ec) return {};
    const fs::path r = file.lexically_relative(root);
    if (r.empty() || *r.begin() == ".." || r == ".") return {};
    return file;
}

} // namespace iblcheck
