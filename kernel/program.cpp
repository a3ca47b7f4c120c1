#include "kernel/program.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <unistd.h>

#include "kernel/hash.h"
#include "kernel/shell_quote.h"

namespace fs = std::filesystem;

namespace iblcheck {

namespace {
std::string& name_storage() {
    static std::string name = "iblcheck";
    return name;
}

// The file `iblcheck` resolves to through PATH, as the shell finds it (empty when none).
fs::path on_path() {
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::stringstream dirs(path);
    std::error_code ec;
    for (std::string dir; std::getline(dirs, dir, ':');) {
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / "iblcheck";
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    return {};
}
} // namespace

const std::string& program_name() { return name_storage(); }
void set_program_name(const std::string& name) { name_storage() = name; }

std::string program_from_self() {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec || self.empty()) return "iblcheck";
    if (const fs::path p = on_path(); !p.empty() && fs::equivalent(p, self, ec)) return "iblcheck";
    const fs::path cwd = fs::current_path(ec);
    std::string rel = ec ? std::string() : self.lexically_relative(cwd).string();
    if (!rel.empty() && rel.find('/') == std::string::npos) rel = "./" + rel; // a bare name would search PATH
    const std::string best = !rel.empty() && rel.size() < self.string().size() ? rel : self.string();
    return shell_arg(best);
}

std::string file_content_hash(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return "";
    Fnv1a64 h;
    std::vector<char> buf(1 << 20);
    while (f.read(buf.data(), std::streamsize(buf.size())) || f.gcount() > 0) h.update(buf.data(), size_t(f.gcount()));
    return f.bad() ? "" : h.hex();
}

// Defined by the iblcheck binary (its generated render_code_hash.cpp and metrics_code_hash.cpp);
// these weak ones stand in for them in every other program.
extern "C" __attribute__((weak)) const char* iblcheck_render_code_hash_generated() { return nullptr; }
extern "C" __attribute__((weak)) const char* iblcheck_metrics_code_hash_generated() { return nullptr; }

namespace {
// "<kind>-code:<hash>" when the build generated the hash, else the running binary's.
std::string code_hash(const char* kind, const char* built) {
    return built && *built ? std::string(kind) + "-code:" + built : running_binary_hash();
}
} // namespace

const std::string& render_code_hash() {
    static const std::string hash = code_hash("render", iblcheck_render_code_hash_generated());
    return hash;
}

const std::string& metrics_code_hash() {
    static const std::string hash = code_hash("metrics", iblcheck_metrics_code_hash_generated());
    return hash;
}

const std::string& running_binary_hash() {
    static const std::string hash = [] {
        std::string h = file_content_hash("/proc/self/exe");
        return h.empty() ? std::string("unreadable") : h;
    }();
    return hash;
}

} // namespace iblcheck
