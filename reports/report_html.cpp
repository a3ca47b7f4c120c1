// Helpers shared by the report's pieces (report_html.h).
#include "reports/report_html.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "kernel/output_files.h"

namespace iblcheck::report::html {

namespace fs = std::filesystem;

std::string str(const json& j, const char* k) {
    if (!j.is_object()) return "";
    auto it = j.find(k);
    if (it == j.end() || !it->is_string()) return "";
    return it->get<std::string>();
}
std::optional<double> num(const json& j, const char* k) {
    if (!j.is_object()) return std::nullopt;
    auto it = j.find(k);
    if (it == j.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
}
const json& sub(const json& j, const char* k) {
    static const json null_json;
    if (!j.is_object()) return null_json;
    auto it = j.find(k);
    return it == j.end() ? null_json : *it;
}
std::string value_text(const json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number()) return fmt_num(v.get<double>());
    if (v.is_null()) return "";
    return v.dump();
}

std::string run_commit(const json& r) { return str(r, "commit") + (r.value("dirty", false) ? "+dirty" : ""); }

const std::vector<std::string>& verdict_order() {
    static const std::vector<std::string> order{"fail", "error", "missing-golden", "improved", "pass"};
    return order;
}
int verdict_rank(const std::string& v) {
    const auto& o = verdict_order();
    return int(std::find(o.begin(), o.end(), v) - o.begin());
}
bool needs_bless(const std::string& v) { return v == "fail" || v == "missing-golden" || v == "improved"; }

std::string method_color(const std::string& m) {
    if (m == "mobile") return "#e8590c";
    if (m == "sampled") return "#1c7ed6";
    if (m == "reference") return "#2f9e44";
    static const char* pal[] = {"#ae3ec9", "#f59f00", "#0ca678", "#d6336c", "#495057", "#3b5bdb"};
    return pal[std::hash<std::string>{}(m) % 6];
}

std::string test_id(size_t i) { return fmt::format("t-{}", i); }

std::string test_label(const json& t) {
    std::string l = str(t, "method");
    if (!str(t, "variant").empty()) l += (l.empty() ? "" : " ") + str(t, "variant");
    return l.empty() ? str(t, "name") : l;
}

std::string variant_family(const json& t) {
    const json& o = sub(t, "options");
    std::string v = str(t, "variant");
    if (v.empty() || v == "default" || v == "temporal") return "default";
    // Keys of the variant ("k=v,k=v"), in its order.
    std::string fam;
    size_t start = 0;
    while (start < v.size()) {
        size_t end = v.find(',', start);
        std::string part = v.substr(start, end == std::string::npos ? std::string::npos : end - start);
        std::string key = part.substr(0, part.find('='));
        if (!o.is_object() || o.contains(key) || o.empty()) fam += (fam.empty() ? "" : "+") + key;
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return fam.empty() ? "default" : fam;
}

// The overview shows the first line of a message, cut at a word near 160 characters (UTF-8 safe).
std::string short_message(const std::string& m) {
    std::string s = m.substr(0, m.find('\n'));
    if (s.size() <= 160) return s == m ? s : s + " \u2026";
    size_t cut = s.rfind(' ', 160);
    if (cut == std::string::npos || cut < 100) {
        cut = 160;
        while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
    }
    return s.substr(0, cut) + " \u2026";
}

namespace {
std::string url_encode_path(const std::string& p) {
    std::string o;
    for (unsigned char c : p) {
        if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/')
            o += char(c);
        else
            o += fmt::format("%{:02X}", c);
    }
    return o;
}
} // namespace

ImageStore::ImageStore(fs::path results_dir, fs::path out_dir)
    : results_dir_(std::move(results_dir)), out_dir_(std::move(out_dir)) {}

std::optional<std::string> ImageStore::url(const std::string& rel) {
    if (rel.empty()) return std::nullopt;
    if (auto it = done_.find(rel); it != done_.end()) return it->second;
    std::optional<std::string> result;
    fs::path p(rel);
    const fs::path src = inside_folder(results_dir_, rel); // a tampered results file names any file
    std::error_code ec;
    if (src.empty()) {
        missing_.push_back(rel + " (outside the run's folder: not read)");
    } else if (!fs::is_regular_file(src, ec)) {
        missing_.push_back(rel);
    } else {
        bool clean = !p.is_absolute() && !p.empty();
        for (const auto& part : p)
            if (part == ".." || part == ".") clean = false;
        fs::path dest_rel =
            clean ? p : fs::path("images/_external") / (std::to_string(++external_) + "_" + p.filename().string());
        fs::path dest = out_dir_ / dest_rel;
        if (!(fs::exists(dest, ec) && fs::equivalent(src, dest, ec))) {
            fs::create_directories(dest.parent_path(), ec);
            if (!fs::copy_file(src, dest, fs::copy_options::overwrite_existing, ec))
                throw Error(fmt::format("{}: cannot copy image into the report: {}", dest.string(), ec.message()));
        }
        result = url_encode_path(dest_rel.generic_string());
    }
    done_[rel] = result;
    return result;
}

bool ImageStore::exists(const std::string& rel) const {
    std::error_code ec;
    const fs::path src = inside_folder(results_dir_, rel);
    return !src.empty() && fs::is_regular_file(src, ec);
}

} // namespace iblcheck::report::html
