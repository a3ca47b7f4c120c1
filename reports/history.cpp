// The history file: JSON lines, one compact entry per run (results/RESULTS_FORMAT.md, "History").
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "metrics/catalog.h"
#include "reports/report_writer.h"

namespace iblcheck::report {

using json = nlohmann::json;

std::vector<json> read_history(const std::filesystem::path& file) {
    std::vector<json> out;
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) return out;
    std::ifstream in = open_input_file(file.string());
    std::string line;
    size_t lineno = 0;
    while (std::getline(in, line)) {
        ++lineno;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        json j;
        try {
            j = json::parse(line);
        } catch (const json::exception& e) {
            throw InputError(fmt::format("{}:{}: not a JSON line: {}", file.string(), lineno, e.what()));
        }
        if (!j.is_object() || !j.contains("tests") || !j["tests"].is_object())
            throw InputError(
                fmt::format("{}:{}: a history line must be an object with a \"tests\" object", file.string(), lineno));
        out.push_back(std::move(j));
    }
    return out;
}

json history_entry(const json& results) {
    json e = json::object();
    auto str = [&](const char* k) { return results.contains(k) && results[k].is_string() ? results[k] : json(""); };
    e["commit"] = str("commit");
    e["dirty"] = results.value("dirty", false);
    e["date"] = str("started");
    e["suite"] = str("suite");
    json tests = json::object();
    if (results.contains("tests") && results["tests"].is_array())
        for (const json& t : results["tests"]) {
            if (!t.is_object() || !t.contains("name") || !t["name"].is_string()) continue;
            json x = json::object();
            x["verdict"] = t.value("verdict", "");
            // The mean HDR-FLIP against the truth, under the three names it has (metrics/catalog.h):
            // the result's accuracy summary and the history ("flip_mean"), stability's noise floor
            // ("accuracy.flip.mean"), the truth's sidecar ("mean_flip").
            const MetricInfo& flip = metric("flip.mean");
            if (auto a = t.find("accuracy"); a != t.end() && a->is_object())
                if (auto f = a->find(flip.accuracy_name); f != a->end() && f->is_number()) x[flip.accuracy_name] = *f;
            for (const char* k : {"frame_ms", "precompute_ms"})
                if (auto v = t.find(k); v != t.end() && v->is_number()) x[k] = *v;
            // The accuracy's noise floor (drift.h): measured by --stability, else the truth's own seed noise.
            if (auto st = t.find("stability"); st != t.end() && st->is_object())
                if (auto nf = st->find("noise_floor"); nf != st->end() && nf->is_object())
                    if (auto f = nf->find("accuracy." + std::string(flip.key)); f != nf->end() && f->is_number())
                        x["flip_noise"] = *f;
            if (!x.contains("flip_noise"))
                if (auto a = t.find("accuracy"); a != t.end() && a->is_object())
                    if (auto nf = a->find("noise_floor"); nf != a->end() && nf->is_object())
                        if (auto f = nf->find(flip.truth_noise_name); f != nf->end() && f->is_number()) x["flip_noise"] = *f;
            // The repeated timings' range (suite timing_repeats); frame_ms is their median.
            if (auto sm = t.find("frame_ms_samples"); sm != t.end() && sm->is_array() && !sm->empty()) {
                double lo = INFINITY, hi = -INFINITY;
                for (const json& v : *sm)
                    if (v.is_number()) lo = std::min(lo, v.get<double>()), hi = std::max(hi, v.get<double>());
                if (std::isfinite(lo) && std::isfinite(hi)) {
                    x["frame_ms_lo"] = lo;
                    x["frame_ms_hi"] = hi;
                    x["frame_n"] = sm->size();
                }
            }
            if (auto c = t.find("cost"); c != t.end() && c->is_object())
                if (auto i = c->find("spirv_instructions_per_pixel"); i != c->end() && i->is_number()) x["spirv_ipp"] = *i;
            if (auto tp = t.find("temporal"); tp != t.end() && tp->is_object())
                if (auto f = tp->find("flicker"); f != tp->end() && f->is_number()) x["flicker"] = *f;
            tests[t["name"].get<std::string>()] = std::move(x);
        }
    e["tests"] = std::move(tests);
    return e;
}

namespace {
struct Fd {
    int fd;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};
} // namespace

// Validated before anything is written (a file truncated mid-line used to get the new entry glued
// onto its last line, and every later run then failed on it), under a lock (two runs append in
// turn), in one write that is undone if it fails part way (a full disk).
std::vector<json> append_history(const std::filesystem::path& file, const json& entry) {
    std::error_code ec;
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
    const Fd f{::open(file.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644)};
    if (f.fd < 0 || ::flock(f.fd, LOCK_EX) != 0)
        throw InputError(fmt::format("{}: cannot append to the history file: {}", file.string(), std::strerror(errno)));
    std::vector<json> history = read_history(file);
    const off_t size = ::lseek(f.fd, 0, SEEK_END);
    char last = '\n';
    if (size > 0 && ::pread(f.fd, &last, 1, size - 1) != 1) last = '\n';
    // A last line without its newline that still parses is kept whole: the entry starts a line.
    const std::string line = (last == '\n' ? "" : "\n") + entry.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
    if (::write(f.fd, line.data(), line.size()) != ssize_t(line.size())) {
        const int err = errno;
        if (::ftruncate(f.fd, size) != 0) {}
        throw InputError(fmt::format("{}: cannot append to the history file: {}", file.string(), std::strerror(err)));
    }
    history.push_back(entry);
    return history;
}

} // namespace iblcheck::report
