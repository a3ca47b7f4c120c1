#include "bless.h"

#include <fmt/core.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <regex>

#include "golden_store.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "kernel/input_file.h"
#include "kernel/program.h"
#include "kernel/shell_quote.h"
#include "metrics/catalog.h"
#include "metrics/identical.h"
#include "metrics/image_compare.h"
#include "provenance.h"
#include "renderers/environments/environment.h"
#include "verdict.h"
#include "worker.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {
json read_sidecar(const fs::path& exr) {
    const fs::path side = fs::path(exr).replace_extension(".json");
    if (!fs::exists(side)) return json();
    std::ifstream f = open_input_file(side.string()); // a FIFO would block: refused
    return json::parse(f, nullptr, false);
}

// The accuracy against the reference golden that the reference band is built on. A test that asks
// for the truth must have it: a golden blessed without its accuracy used to drop the check silently.
json approved_accuracy(const GoldenStore& store, const TestCase& tc, const RenderResult& rr) {
    const cv::Mat& image = rr.image;
    if (!tc.reference) return json::object();
    auto ref = store.reference(tc.spec);
    if (!ref)
        throw InputError(store.reference_path(tc.spec).string() +
                         ": no reference golden, and the test asks for one (\"reference\": true); create it with: " +
                         truth_command(tc.spec, store));
    // An edited environment file: the truth was made from other pixels, so the accuracy would be wrong.
    const std::string truth_hash = truth_env_hash(ref->provenance);
    const std::string now = rr.provenance.contains("env_hash") ? rr.provenance["env_hash"].get<std::string>() : "";
    if (is_environment_file(tc.spec.env) && !truth_hash.empty() && truth_hash != now)
        throw InputError(fmt::format("{}: its content changed since {} was made from it (content hash {} there, {} now); "
                                     "re-render the truth with: {}",
                                     tc.spec.env, ref->image_path.string(), truth_hash, now, truth_command(tc.spec, store)));
    if (ref->image.size() != image.size())
        throw InputError(fmt::format("{}: {}x{}, but the render is {}x{}", ref->image_path.string(), ref->image.cols,
                                     ref->image.rows, image.cols, image.rows));
    json m = compare_images(ref->image, image, 0, nullptr, tc.display ? &*tc.display : nullptr);
    json a = json::object();
    for (const MetricInfo* k : judged_metrics(tc.display.has_value())) // a display test's reference_band: its display figures too
        a[k->key] = m[k->group][k->field];
    return a;
}

// What changed against the baseline already there: "new", "unchanged", or how it changed.
struct Change {
    bool pixels = true, judged = true; // pixels differ; a judged figure of the sidecar differs
    std::string text = "new";
};

Change change_against(const fs::path& path, const cv::Mat& image, const json& prov) {
    Change c;
    if (!fs::exists(path)) return c;
    cv::Mat old = read_image(path.string()).pixels;
    json oldp = read_sidecar(path);
    c.pixels = !bit_identical(old, image);
    c.judged = !oldp.is_object() || oldp.value("accuracy", json()) != prov["accuracy"] ||
               oldp.value("cost", json()) != prov["cost"] || oldp.value("size", json()) != prov["size"];
    if (!c.pixels)
        c.text = c.judged ? "pixels unchanged; sidecar's accuracy/cost updated" : "unchanged";
    else if (old.size() != image.size())
        c.text = fmt::format("changed size {}x{} -> {}x{}", old.cols, old.rows, image.cols, image.rows);
    else
        c.text = fmt::format("changed: FLIP vs old baseline {:.5f}", compare_images(old, image, 0)["flip"]["mean"].get<double>());
    if (oldp.is_object() && oldp.contains("accuracy") && oldp["accuracy"].contains("flip.mean") &&
        prov["accuracy"].contains("flip.mean") && oldp["accuracy"] != prov["accuracy"])
        c.text += fmt::format("; accuracy FLIP {:.5f} -> {:.5f}", oldp["accuracy"]["flip.mean"].get<double>(),
                              prov["accuracy"]["flip.mean"].get<double>());
    return c;
}

// One line of what bless did, flushed at once: piped into `tee` or a CI log and killed after some
// goldens were written, the output still shows every golden written so far.
template <typename... T> void say(FILE* to, fmt::format_string<T...> f, T&&... args) {
    fmt::print(to, f, std::forward<T>(args)...);
    std::fflush(to);
}

// Holds an exclusive lock on the golden folder while bless reads and writes it: two bless runs at
// once used to both exit 0 and leave goldens of each mixed. The second waits, and says so.
class GoldenLock {
  public:
    explicit GoldenLock(const fs::path& root) {
        std::error_code ec;
        fs::create_directories(root, ec);
        fd_ = ::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (fd_ < 0) throw InputError(root.string() + ": cannot open the golden folder: " + std::strerror(errno));
        if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
        say(stderr, "waiting: another iblcheck bless is writing into {}\n", root.string());
        if (::flock(fd_, LOCK_EX) != 0)
            throw InputError(root.string() + ": cannot lock the golden folder: " + std::strerror(errno));
    }
    ~GoldenLock() { ::close(fd_); }
    GoldenLock(const GoldenLock&) = delete;
    GoldenLock& operator=(const GoldenLock&) = delete;

  private:
    int fd_ = -1;
};

// The new baseline's sidecar: the render's provenance, the test, the approved accuracy and cost,
// the run's provenance (`common`) and the command that blesses it again.
json sidecar(const TestCase& tc, const RenderResult& rr, const GoldenStore& store, const std::optional<std::string>& label,
             const json& common) {
    json prov = rr.provenance;
    prov["test"] = tc.name;
    prov["suite"] = tc.suite;
    prov["method"] = tc.spec.method;
    prov["variant"] = tc.variant;
    prov["size"] = {rr.image.cols, rr.image.rows};
    prov["label"] = label.value_or("");
    prov["accuracy"] = approved_accuracy(store, tc, rr);
    prov["cost"] = render_cost(rr);
    for (auto& [k, v] : common.items()) prov[k] = v;
    prov["command"] = bless_command(tc, "iblcheck") + (label ? " --label " + shell_quote(*label) : "");
    return prov;
}

// A golden file already written for another test (a name that differs only where a file name
// cannot, from another suite) is never overwritten: throws InputError naming both tests.
void check_owner(const fs::path& path, const std::string& test) {
    const json old = read_sidecar(path);
    if (old.is_object() && old.contains("test") && old["test"].is_string() && old["test"] != test)
        throw InputError(fmt::format("{}: is the baseline of test {}, not of {}; the two would share a golden (rename "
                                     "the environment file or change an option)",
                                     path.string(), old["test"].get<std::string>(), test));
}
} // namespace

void check_label(const std::string& label) {
    static const std::regex ok("[A-Za-z0-9._-]+");
    if (!std::regex_match(label, ok))
        throw UsageError("--label '" + label + "': a label is one or more of A-Z a-z 0-9 . _ - (it names a file)");
}

std::string bless_command(const TestCase& t, const std::string& program) {
    const std::string& suite = t.suite_arg.empty() ? t.suite : t.suite_arg;
    return program + " bless --suite " + shell_quote(suite) +
           (t.shader_arg.empty() ? "" : " --shader " + shell_quote(t.shader_arg)) + " --filter " +
           shell_quote(glob_escape(t.name));
}
std::string bless_command(const TestCase& t, const GoldenStore& store) {
    const std::string c = bless_command(t);
    return store.root() == GoldenStore().root() ? c : c + " --goldens " + shell_arg(store.root().string());
}

int bless(const BlessOptions& o) {
    if (o.label) check_label(*o.label);
    const std::string label = o.label.value_or("");
    Suite suite = load_suite(o.suite, o.shader);
    std::vector<TestCase> tests = select_tests(suite, o.filter, 0, 1);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    const GoldenLock lock(store.root());
    Worker w(o.device);
    int failed = 0, would = 0;
    const json common = run_provenance();
    for (const auto& tc : tests) {
        if (!tc.baseline) continue;
        RenderResult rr;
        try {
            rr = w.renderer.render(tc.spec);
            if (NonFinite nf = find_non_finite(rr.image); nf.count) throw NonFiniteRender(nf.describe());
        } catch (const std::exception& e) {
            say(stderr, "error: {}: render failed, not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        json prov;
        try {
            prov = sidecar(tc, rr, store, o.label, common);
        } catch (const Error& e) {
            say(stderr, "error: {}: not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        const fs::path path = store.baseline_path(tc.name, label);
        try {
            check_owner(path, tc.name);
        } catch (const InputError& e) {
            say(stderr, "error: {}: not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        Change change = change_against(path, rr.image, prov);
        if (!change.pixels && !change.judged) {
            say(stdout, "{:<9} {}  (unchanged, left as it is)\n", "same", tc.name);
            continue;
        }
        if (o.dry_run) {
            say(stdout, "{:<9} {}  ({})\n", "would", tc.name, change.text);
            ++would;
            continue;
        }
        try {
            if (change.pixels)
                GoldenStore::write_golden(path, rr.image, prov);
            else
                GoldenStore::write_sidecar(path, prov);
        } catch (const std::exception& e) {
            say(stderr, "error: {}: not blessed: {}\n", tc.name, e.what());
            ++failed;
            continue;
        }
        say(stdout, "{:<9} {}  ({})\n", "blessed", tc.name, change.text);
    }
    if (failed) return kExitError;
    // --dry-run as a check (CI: the committed baselines are what bless writes today): 1 when
    // anything would change, like `git diff --exit-code`.
    if (would) say(stdout, "{} baseline(s) would change\n", would);
    return would ? kExitRegression : kExitPass;
}

} // namespace iblcheck
