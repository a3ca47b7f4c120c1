#include "golden_store.h"

#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "image_io/image_formats.h"
#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "kernel/profile.h"
#include "kernel/program.h"
#include "kernel/shell_quote.h"
#include "metrics/identical.h"
#include "renderers/environments/environment.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {
std::string run_capture(const std::string& cmd) {
    std::string out;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return out;
    std::array<char, 256> buf;
    while (fgets(buf.data(), buf.size(), p)) out += buf.data();
    pclose(p);
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

// A golden is its image and its sidecar: a golden without a sidecar has lost its provenance and
// its approved accuracy (the reference band would be silently dropped), and one with NaN/Inf
// pixels judges nothing. Both are input errors naming the file.
Golden load_golden(const fs::path& exr, const std::string& label) {
    ProfileStage stage("golden_read");
    Golden g;
    g.image_path = exr;
    g.label = label;
    // A golden is what bless and truth write: an OpenEXR of R, G, B floats. A PNG named .exr or a
    // Y-only EXR used to be compared as one (and so "fail" as a regression).
    LoadedImage loaded = read_image(exr.string());
    if (imagefile::sniff_format(exr.string()) != imagefile::Format::exr)
        throw InputError(exr.string() + ": not an OpenEXR file (a golden is the float R, G, B image bless or truth wrote)");
    if (loaded.file_channels != 3)
        throw InputError(exr.string() + ": " + std::to_string(loaded.file_channels) +
                         " channel(s); a golden holds R, G, B (as bless and truth write it)");
    g.image = std::move(loaded.pixels);
    check_finite(g.image, exr.string());
    fs::path side = fs::path(exr).replace_extension(".json");
    if (!fs::exists(side))
        throw InputError(side.string() + ": golden sidecar missing (every golden has one; re-create the golden with "
                                         "iblcheck bless, or scripts/regenerate_reference_goldens.sh for the truth)");
    try {
        std::ifstream f = open_input_file(side.string());
        g.provenance = json::parse(f);
    } catch (const json::exception& e) {
        throw InputError(side.string() + ": corrupt golden sidecar: " + e.what());
    }
    if (!g.provenance.is_object()) throw InputError(side.string() + ": golden sidecar is not a JSON object");
    return g;
}
} // namespace

std::string safe_file_name(const std::string& name) {
    std::string s = name;
    for (char& ch : s)
        if (ch == '/' || ch == ':' || ch == '\\' || ch == ' ' || ch == '*' || ch == '?') ch = '-';
    return s;
}

namespace {
// The options that change the true image (and so its key).
const std::set<std::string> kMaterialOptions = {"roughness", "metallic", "base_color", "env_rotation", "ao"};
} // namespace

std::string reference_key(const TestSpec& spec) {
    std::string key = spec.scene + "__" + safe_file_name(environment_label(spec.env, spec.env_name));
    std::string extra;
    for (auto& [k, v] : spec.options.values())
        if (kMaterialOptions.count(k)) extra += (extra.empty() ? "" : ",") + k + "=" + v;
    if (!extra.empty()) key += "__" + safe_file_name(extra);
    if (spec.width > 0) key += "__" + std::to_string(spec.width) + "x" + std::to_string(spec.height);
    return key;
}

std::string reference_sequence_key(const TestSpec& spec, int frames) {
    return reference_key(spec) + "__frames=" + std::to_string(frames);
}

std::string truth_command(const TestSpec& spec, const GoldenStore& store) {
    std::string c = program_name() + " truth --scene " + shell_arg(spec.scene) + " --env " + shell_arg(spec.env);
    if (!spec.env_name.empty()) c += " --env-name " + shell_arg(spec.env_name);
    if (spec.width > 0) c += " --size " + std::to_string(spec.width) + "x" + std::to_string(spec.height);
    for (auto& [k, v] : spec.options.values())
        if (kMaterialOptions.count(k)) c += " --set " + shell_arg(k + "=" + v);
    if (store.root() != GoldenStore().root()) c += " --goldens " + shell_arg(store.root().string());
    return c;
}

std::string truth_env_hash(const json& sidecar) {
    const json env = sidecar.is_object() ? sidecar.value("env", json()) : json();
    return env.is_object() && env.contains("content_hash") && env["content_hash"].is_string()
               ? env["content_hash"].get<std::string>()
               : "";
}

GoldenStore::GoldenStore(fs::path root) {
    if (root.empty()) {
        if (const char* e = std::getenv("IBLCHECK_GOLDEN_DIR"); e && *e)
            root = e;
        else
            root = fs::path(IBLCHECK_SOURCE_DIR) / "goldens";
    }
    root_ = root;
}

void GoldenStore::check_root() const {
    std::error_code ec;
    if (!fs::is_directory(root_, ec))
        throw InputError(root_.string() + ": " + (fs::exists(root_, ec) ? "not a folder" : "no such folder") +
                         ": not a golden root (--goldens or IBLCHECK_GOLDEN_DIR)");
    if (!fs::is_directory(root_ / "baseline", ec) && !fs::is_directory(root_ / "reference", ec))
        throw InputError(root_.string() +
                         ": no baseline/ or reference/ folder: not a golden root (--goldens or IBLCHECK_GOLDEN_DIR)");
}

std::string GoldenStore::relative(const fs::path& p) const {
    fs::path r = p.lexically_relative(root_);
    return r.empty() || *r.begin() == ".." ? p.string() : r.string();
}

fs::path GoldenStore::baseline_path(const std::string& test_name, const std::string& label) const {
    return root_ / "baseline" / (safe_file_name(test_name) + (label.empty() ? "" : "@" + label) + ".exr");
}

fs::path GoldenStore::reference_path(const TestSpec& spec) const { return root_ / "reference" / (reference_key(spec) + ".exr"); }

std::vector<Golden> GoldenStore::baselines(const std::string& test_name) const {
    std::vector<Golden> out;
    fs::path primary = baseline_path(test_name);
    if (fs::exists(primary)) out.push_back(load_golden(primary, ""));
    fs::path dir = root_ / "baseline";
    std::string prefix = safe_file_name(test_name) + "@";
    if (fs::is_directory(dir)) {
        std::vector<fs::path> alts;
        for (auto& e : fs::directory_iterator(dir)) {
            std::string f = e.path().filename().string();
            if (e.path().extension() == ".exr" && f.rfind(prefix, 0) == 0) alts.push_back(e.path());
        }
        std::sort(alts.begin(), alts.end());
        for (auto& p : alts) {
            std::string stem = p.stem().string();
            out.push_back(load_golden(p, stem.substr(prefix.size())));
        }
    }
    return out;
}

fs::path GoldenStore::reference_sequence_path(const TestSpec& spec, int frames) const {
    return root_ / "reference" / (reference_sequence_key(spec, frames) + ".exr");
}

std::optional<Golden> GoldenStore::reference_sequence(const TestSpec& spec, int frames, std::vector<cv::Mat>& out) const {
    out.clear();
    const fs::path p = reference_sequence_path(spec, frames);
    if (!fs::exists(p)) return std::nullopt;
    Golden g = load_golden(p, "");
    if (frames < 1 || g.image.rows % frames != 0)
        throw InputError(p.string() + ": " + std::to_string(g.image.rows) + " rows are not " + std::to_string(frames) +
                         " stacked frames");
    const int h = g.image.rows / frames;
    for (int f = 0; f < frames; ++f) out.push_back(g.image.rowRange(f * h, (f + 1) * h).clone());
    return g;
}

namespace {
// A file's identity for the reference cache: its size and modification time (the golden writer renames
// a new file over the old, so a rewritten golden has a new time).
std::string file_stamp(const fs::path& p) {
    std::error_code ec;
    const auto size = fs::file_size(p, ec);
    const auto time = fs::last_write_time(p, ec).time_since_epoch().count();
    return ec ? std::string("?") : std::to_string(size) + "@" + std::to_string(time);
}

// The truth goldens a process has read, by path and the stamps of the EXR and its sidecar: a truth is
// the reference of many tests (the ci suite read the roughness sweep's two 43 times, 9 % of a warm
// run's worker time, issue 33). A few are kept; each caller gets its own copy of the pixels.
Golden load_reference(const fs::path& exr) {
    static std::mutex mutex;
    static std::map<std::string, Golden> loaded;
    const std::string key =
        fs::absolute(exr).string() + "|" + file_stamp(exr) + "|" + file_stamp(fs::path(exr).replace_extension(".json"));
    {
        std::lock_guard lock(mutex);
        if (auto it = loaded.find(key); it != loaded.end()) {
            Golden g = it->second;
            g.image = g.image.clone();
            return g;
        }
    }
    Golden g = load_golden(exr, "");
    std::lock_guard lock(mutex);
    if (loaded.size() >= 8) loaded.clear();
    Golden kept = g;
    kept.image = g.image.clone();
    loaded.emplace(key, std::move(kept));
    return g;
}
} // namespace

std::optional<Golden> GoldenStore::reference(const TestSpec& spec) const {
    fs::path p = reference_path(spec);
    if (!fs::exists(p)) return std::nullopt;
    return load_reference(p);
}

void GoldenStore::write_sidecar(const fs::path& exr, const json& provenance) {
    write_file_atomically(fs::path(exr).replace_extension(".json"), provenance.dump(2) + "\n");
}

namespace {
// Whether the golden `exr` holds exactly `image`'s pixels, bit for bit (false when absent or unreadable).
bool same_pixels(const fs::path& exr, const cv::Mat& image) {
    std::error_code ec;
    if (!fs::exists(exr, ec)) return false;
    try {
        const cv::Mat old = read_image(exr.string()).pixels;
        return bit_identical(old, image);
    } catch (const Error&) {
        return false; // unreadable: replaced
    }
}
} // namespace

void GoldenStore::write_golden(const fs::path& exr, const cv::Mat& image, const json& provenance) {
    std::error_code ec;
    if (exr.has_parent_path()) fs::create_directories(exr.parent_path(), ec); // `truth --out g.exr`: the current folder
    if (ec) throw InputError(exr.parent_path().string() + ": cannot create the golden folder: " + ec.message());
    // Bit-identical pixels keep their file (a deterministic truth regenerated unchanged): the sidecar alone.
    if (same_pixels(exr, image)) return write_sidecar(exr, provenance);
    write_file_atomically(exr, [&](const fs::path& tmp) {
        write_exr(tmp.string(), image);
        // The sidecar before the image is renamed in: a reader that sees the new image finds its provenance.
        write_sidecar(exr, provenance);
    });
}

std::string project_commit(bool* dirty) {
    std::string dir = IBLCHECK_SOURCE_DIR;
    std::string c = run_capture("git -C '" + dir + "' rev-parse --short=12 HEAD 2>/dev/null");
    if (dirty) *dirty = !run_capture("git -C '" + dir + "' status --porcelain --untracked-files=no 2>/dev/null").empty();
    return c.empty() ? "unknown" : c;
}

std::string utc_now_iso() {
    std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

std::vector<std::string> cpu_features() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    std::vector<std::string> out;
    static const std::set<std::string> wanted = {"sse4_2", "avx", "avx2", "fma", "f16c", "avx512f", "avx512bw", "neon", "asimd"};
    while (std::getline(f, line)) {
        if (line.rfind("flags", 0) != 0 && line.rfind("Features", 0) != 0) continue;
        std::istringstream ss(line.substr(line.find(':') + 1));
        std::string w;
        while (ss >> w)
            if (wanted.count(w)) out.push_back(w);
        break;
    }
    return out;
}

} // namespace iblcheck
