#include "runner.h"

#include <unistd.h>

#include <fmt/core.h>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>

#include "kernel/errors.h"
#include "kernel/output_files.h"
#include "kernel/parallel_for.h"
#include "kernel/profile.h"
#include "one_test.h"
#include "provenance.h"
#include "renderers/renderer.h"
#include "reports/report_writer.h"
#include "run_console.h"
#include "run_files.h"
#include "run_profile.h"
#include "timing_groups.h"
#include "verdict.h"
#include "worker.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

// What the workers leave: each test's results object in suite order, and the run's facts.
struct PoolOutcome {
    std::vector<TestResult> results;
    json driver;
    bool shader_error = false;
};

// The tests on `jobs` worker threads (at most one a batch), each with its own renderer, taking batches
// of tests from the queue (batch_queue.h) as it finishes one; a line per test as it finishes unless
// quiet. Results stay in suite order.
PoolOutcome run_tests(const std::vector<TestCase>& tests, const RunOptions& o, const fs::path& out_dir, const GoldenStore& store,
                      int jobs, int timing_repeats) {
    const int flip_threads = jobs > 1 ? 1 : 0;
    std::vector<TestResult> results(tests.size());
    const std::vector<ChainBatches> chains = precompute_batches(tests);
    size_t batches = 0;
    for (const ChainBatches& c : chains) batches += c.size();
    BatchQueue queue(chains);
    const std::vector<int> renders = timing_renders(tests, timing_repeats); // tests of a timing group share theirs
    std::atomic<int> done{0};
    std::atomic<bool> shader_error{false};
    std::mutex print_mutex;
    const bool interactive = isatty(STDOUT_FILENO);
    ConsoleBudget budget;
    // A worker's state is its GPU session (made on its own thread); a worker that cannot make one (no
    // device) stops the run, and its error is rethrown here. Worker `worker` keeps to its chain.
    const auto run_batches = [&](int worker, std::unique_ptr<Worker>& w) {
        while (const std::optional<Batch> batch = queue.next(worker))
            for (size_t i : *batch) {
                bool se = false;
                TestCase tc = tests[i];
                if (o.stability) tc.stability.enabled = true;
                results[i] = run_test(tc, *w, store, out_dir, flip_threads, renders[i], se);
                if (se) shader_error = true;
                int n = ++done;
                if (!o.quiet) {
                    std::lock_guard lock(print_mutex);
                    print_test_line(to_json(results[i]), n, tests.size(), interactive, budget);
                }
            }
    };
    const auto workers = parallel_for(
        int(std::min<size_t>(size_t(std::max(jobs, 1)), batches)), jobs,
        [&] {
            try {
                auto w = std::make_unique<Worker>(o.device);
                w->stored_sequences = o.stored_sequences;
                return w;
            } catch (...) {
                queue.close(); // the other workers stop after their batch
                throw;
            }
        },
        [&](int worker, std::unique_ptr<Worker>& w) {
            try {
                run_batches(worker, w);
            } catch (...) {
                queue.close();
                throw;
            }
        });
    share_timings(tests, timing_repeats, results);
    json driver;
    for (const auto& w : workers)
        if (json d = w->renderer.driver_json(); !d.empty()) driver = d;
    return {std::move(results), std::move(driver), shader_error};
}

// What a run records about its start: the time and the provenance (commit, CPU), taken before the
// first test. Taken after the tests, a nightly recorded its end as its start and the commit checked
// out by then (a bisect or a pull during the run), not the one it ran.
struct RunStart {
    std::string started = utc_now_iso();
    json provenance = run_provenance();
};

// The results document (results/RESULTS_FORMAT.md): the run's facts, every test, the counts.
void record_run(RunSummary& s, const std::string& suite, const RunOptions& o, const RunStart& start, PoolOutcome& pool,
                double total_s) {
    RunResults run;
    run.suite = suite;
    run.command = o.command_line;
    run.started = start.started;
    run.total_s = total_s;
    const json& prov = start.provenance;
    std::string commit = prov["commit"];
    run.dirty = commit.size() > 6 && commit.substr(commit.size() - 6) == "-dirty";
    run.commit = run.dirty ? commit.substr(0, commit.size() - 6) : commit;
    run.driver = pool.driver;
    run.cpu_features = prov["cpu_features"];
    run.cpu_class = prov["cpu_class"].get<std::string>();
    run.shard = fmt::format("{}/{}", o.shard_index, o.shard_count);
    for (const TestResult& r : pool.results) s.add(r.verdict);
    run.tests = std::move(pool.results);
    s.results = to_json(run);
    s.shader_compile_error = pool.shader_error;
}

// The files the options ask for: results.json, the JSON copy, JUnit, the history line, the report;
// the run folder is swapped in as --out once all of it is written.
void write_outputs(const json& R, const RunOptions& o, RunFolder& folder) {
    const fs::path& dir = folder.dir();
    ProfileStage stage("results_and_report");
    if (!dir.empty()) write_json_atomically(dir / "results.json", R);
    if (!o.json.empty()) write_json_atomically(o.json, R);
    if (!o.junit.empty()) write_junit(R, o.junit);
    std::vector<json> history;
    if (!o.history.empty()) history = append_history(o.history, history_entry(R));
    if (!dir.empty() && o.report) write_report(R, dir, dir, history, o.findings);
    folder.commit();
}

// The files named by options, checked before anything is rendered: none overwritten without
// --force, none the same as an input, none inside --out (which is replaced whole).
void check_output_options(const RunOptions& o, const Suite& suite) {
    check_output_file(o.json, "--json", o.force, {suite.file, o.history});
    check_output_file(o.junit, "--junit", o.force, {suite.file, o.history});
    check_distinct_outputs(o.json, "--json", o.junit, "--junit");
    if (!o.history.empty()) read_history(o.history); // a malformed history fails now, not after the renders
    if (o.out_dir.empty()) return;
    std::error_code ec;
    const fs::path out = fs::weakly_canonical(fs::absolute(o.out_dir), ec);
    const std::pair<fs::path, const char*> named[] = {{o.json, "--json"}, {o.junit, "--junit"}, {o.history, "--history"}};
    for (const auto& [file, option] : named) {
        if (file.empty()) continue;
        const fs::path rel = fs::weakly_canonical(fs::absolute(file), ec).lexically_relative(out);
        if (!rel.empty() && *rel.begin() != "..")
            throw UsageError(std::string(option) + " " + file.string() + ": inside --out " + o.out_dir.string() +
                             ", which each run replaces whole; give a path outside it");
    }
}

} // namespace

std::vector<ChainBatches> precompute_batches(const std::vector<TestCase>& tests) {
    std::vector<ChainBatches> chains;
    std::map<std::string, size_t> chain_of;
    std::map<std::pair<size_t, std::string>, size_t> batch_of; // (chain, precompute) → batch in that chain
    for (size_t i = 0; i < tests.size(); ++i) {
        std::string chain, full;
        try {
            chain = radiance_chain_share_key(tests[i].spec);
            full = precompute_share_key(tests[i].spec);
        } catch (const std::exception&) {
            chain.clear();
        }
        if (chain.empty()) chain = full = "unshared;" + std::to_string(i); // a bad option, or the CPU truth
        auto [c, new_chain] = chain_of.emplace(chain, chains.size());
        if (new_chain) chains.emplace_back();
        auto [b, new_batch] = batch_of.emplace(std::make_pair(c->second, full), chains[c->second].size());
        if (new_batch) chains[c->second].emplace_back();
        chains[c->second][b->second].push_back(i);
    }
    std::stable_sort(chains.begin(), chains.end(), [](const auto& a, const auto& b) { return tests_in(a) > tests_in(b); });
    return chains;
}

int RunSummary::exit_code() const { return run_exit_code(*this); }

// The suite's history file beside --out when the run names none (suite.h: Suite::history).
RunOptions with_suite_history(RunOptions o, const Suite& suite) {
    if (!o.history.empty() || suite.history.empty() || o.out_dir.empty()) return o;
    fs::path out = fs::absolute(o.out_dir).lexically_normal();
    if (out.filename().empty()) out = out.parent_path(); // "nightly/"
    o.history = out.parent_path() / suite.history;
    return o;
}

RunSummary run_suite(const RunOptions& options) {
    const Suite suite = load_suite(options.suite, options.shader);
    const RunOptions o = with_suite_history(options, suite);
    std::vector<TestCase> tests = select_tests(suite, o.filter, o.shard_index, o.shard_count);
    if (tests.empty()) throw UsageError("no test in suite " + suite.name + " matches --filter '" + o.filter + "'");
    GoldenStore store(o.goldens);
    store.check_root();
    int jobs = o.jobs > 0 ? o.jobs : suite.jobs;
    jobs = std::max(1, std::min<int>(jobs, int(tests.size())));
    check_output_options(o, suite);
    RunFolder folder(o.out_dir, o.force);
    profile::enable(o.profile);
    profile::take(); // this thread's stages before the run (none counted twice)

    const auto t0 = std::chrono::steady_clock::now();
    const RunStart start;
    PoolOutcome pool = run_tests(tests, o, folder.dir(), store, jobs, suite.timing_repeats);
    RunSummary s;
    record_run(s, suite.name, o, start, pool, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    try {
        write_outputs(s.results, o, folder);
    } catch (const InputError& e) { // a full disk: the run is lost, --out is not
        throw InputError(std::string(e.what()) +
                         (o.out_dir.empty() ? "" : "; --out " + o.out_dir.string() + " is left as it was"));
    }
    print_run_summary(s.results, s, tests.size(), o, tests[0].suite_arg,
                      tests[0].shader_arg); // -q drops the per-test lines, never this summary
    if (o.profile)
        print_profile(s.results, profile::take(), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                      jobs);
    return s;
}

} // namespace iblcheck
