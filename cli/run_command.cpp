// `iblcheck run`, `iblcheck bless`, `iblcheck bisect`.
#include <fmt/core.h>

#include "commands.h"
#include "harness/runner.h"
#include "harness/suite.h"
#include "kernel/errors.h"
#include "reports/nightly_findings.h"

namespace iblcheck::cli {

namespace {
void parse_shard(const std::string& s, int& index, int& count) {
    if (s.empty()) return;
    if (std::sscanf(s.c_str(), "%d/%d", &index, &count) != 2)
        throw UsageError("--shard '" + s + "' is not INDEX/COUNT (0-based index)");
}

// Runs the suite `repeat` - 1 more times (no outputs, quiet; temporal sequences rendered whole, not
// read from the store) and prints every verdict that differs from `first`'s; a change turns a pass
// into a regression.
void repeat_runs(const RunOptions& run, RunSummary& first, int repeat, int& exit_code) {
    for (int k = 1; k < repeat; ++k) {
        RunOptions again = run;
        again.out_dir.clear();
        again.junit.clear();
        again.json.clear();
        again.history.clear();
        again.quiet = true;
        again.stored_sequences = false; // every frame rendered again: the repeats look for renders that change
        RunSummary next = run_suite(again);
        int changed = 0;
        for (size_t i = 0; i < first.results["tests"].size(); ++i) {
            const auto& a = first.results["tests"][i];
            const auto& b = next.results["tests"][i];
            if (a["verdict"] != b["verdict"]) {
                ++changed;
                fmt::print("verdict changed on run {}: {} {} -> {}\n", k + 1, a["name"].get<std::string>(),
                           a["verdict"].get<std::string>(), b["verdict"].get<std::string>());
            }
        }
        fmt::print("repeat {}/{}: {} verdict(s) changed\n", k + 1, repeat, changed);
        exit_code = repeat_exit_code(exit_code, changed);
    }
}

void register_run(CLI::App& app, int& exit_code) {
    static RunOptions run;
    static std::string shard, out, junit, json_out, history, goldens;
    static std::vector<std::string> findings;
    auto* r = app.add_subcommand("run", "Run a suite: render, compare with goldens, verdicts, report");
    r->add_option("--suite", run.suite, "Suite name (harness/suites) or a .json path")->capture_default_str();
    r->add_option("--filter", run.filter, "Glob on test names (globs separated by '|'; !GLOB leaves out what it matches)");
    r->add_option("--shader", run.shader, "A team's IBL shading file for every mobile test (docs/SHADER_CONTRACT.md)");
    r->add_option("--shard", shard, "INDEX/COUNT: run one shard (GTest convention, 0-based)");
    r->add_option("--jobs,-j", run.jobs, "Tests in parallel (default: the suite's)");
    r->add_option("--out", out, "Folder for results.json, images and index.html");
    r->add_option("--junit", junit, "JUnit XML file");
    r->add_option("--json", json_out, "Results JSON file");
    r->add_option("--history", history, "Append this run to a history file (JSON lines) and chart it");
    r->add_option("--goldens", goldens, "Golden folder (default: goldens/)");
    r->add_option("--findings", findings, "An `iblcheck explain/explore --json` file for the report's findings (repeatable)");
    r->add_option("--device", run.device, "Vulkan device/driver name substring (default: lavapipe)");
    r->add_flag("--quiet,-q", run.quiet, "No per-test lines (the summary line stays)");
    r->add_flag("--force", run.force,
                "Replace an earlier run's --out folder (whole, once this run is complete) and overwrite --json/--junit files");
    static bool list_only = false;
    r->add_flag("--list", list_only, "Print the selected tests' names and exit");
    r->add_flag("--stability", run.stability, "Also measure determinism, noise floors, sensitivity and margins");
    r->add_flag("--profile", run.profile,
                "Print where the time went: per stage (precompute, ASTC, SPIR-V, pipelines, "
                "shading, the counting twin, metrics, files, report) and the slowest tests");
    static int repeat = 1;
    r->add_option("--repeat", repeat, "Run the suite N times; exit 1 if any verdict changes between runs")
        ->check(CLI::Range(1, 100));
    r->callback([&exit_code] {
        parse_shard(shard, run.shard_index, run.shard_count);
        if (const char* gi = std::getenv("GTEST_SHARD_INDEX"); gi && shard.empty()) run.shard_index = std::atoi(gi);
        if (const char* gt = std::getenv("GTEST_TOTAL_SHARDS"); gt && shard.empty()) run.shard_count = std::atoi(gt);
        run.out_dir = out;
        run.junit = junit;
        run.json = json_out;
        run.history = history;
        for (const std::string& f : findings) run.findings.push_back(report::read_findings(f));
        run.goldens = goldens;
        run.command_line = invocation();
        if (list_only) {
            for (const auto& t : select_tests(load_suite(run.suite, run.shader), run.filter, run.shard_index, run.shard_count))
                fmt::print("{}\n", t.name);
            exit_code = kExitPass;
            return;
        }
        RunSummary first = run_suite(run);
        exit_code = first.exit_code();
        repeat_runs(run, first, repeat, exit_code);
    });
}

void register_bless(CLI::App& app, int& exit_code) {
    static BlessOptions bo;
    static std::string bless_goldens, label;
    auto* b = app.add_subcommand("bless", "Re-render and write baseline goldens (the only writer of goldens)");
    b->add_option("--suite", bo.suite, "Suite name or path")->capture_default_str();
    b->add_option("--filter", bo.filter, "Glob on test names (default: every test of the suite)");
    b->add_option("--shader", bo.shader, "A team's IBL shading file for every mobile test (as `run --shader`)");
    auto* label_opt = b->add_option("--label", label,
                                    "Write an alternate approved baseline <test>@LABEL for a known platform difference "
                                    "(LABEL: A-Z a-z 0-9 . _ -)");
    b->add_option("--goldens", bless_goldens, "Golden folder (default: goldens/)");
    b->add_option("--device", bo.device, "Vulkan device/driver name substring");
    b->add_flag("--dry-run", bo.dry_run, "Show what would change, write nothing; exit 1 if anything would change");
    b->callback([&exit_code, label_opt] {
        bo.goldens = bless_goldens;
        if (label_opt->count() > 0) bo.label = label; // given, even empty: check_label refuses ""
        exit_code = bless(bo);
    });
}

// The `git bisect run` contract: 0 good, 1 bad, 125 cannot test.
void register_bisect(CLI::App& app, int& exit_code) {
    static RunOptions bis;
    static std::string bis_goldens;
    auto* s =
        app.add_subcommand("bisect", "git bisect run contract: exit 0 good, 1 bad, 125 anything else (cannot test this commit)");
    s->add_option("--suite", bis.suite, "Suite name or path")->capture_default_str();
    s->add_option("--filter", bis.filter, "Glob on test names (required: keep it to the failing tests)")->required();
    s->add_option("--goldens", bis_goldens, "Golden folder to judge against (copy the good goldens out of the tree)");
    s->add_option("--device", bis.device, "Vulkan device/driver name substring");
    s->callback([&exit_code] {
        bis.goldens = bis_goldens;
        bis.report = false;
        RunSummary sum;
        // Only a verdict on the commit is 0 or 1: anything else (a filter matching nothing, a wrong
        // --goldens, a corrupt golden, no driver, a shader that does not compile) is 125, which git
        // bisect skips. Exit 2 or 1 for them made it name the wrong commit.
        try {
            sum = run_suite(bis);
        } catch (const std::exception& e) {
            fmt::print(stderr, "cannot test: {}\n", e.what());
            exit_code = kExitCannotTest;
            fmt::print("bisect verdict: {}\n", bisect_verdict_name(exit_code));
            return;
        }
        exit_code = bisect_exit_code(sum, sum.shader_compile_error); // harness/verdict.h
        fmt::print("bisect verdict: {}\n", bisect_verdict_name(exit_code));
    });
}

} // namespace

void register_run_commands(CLI::App& app, int& exit_code) {
    register_run(app, exit_code);
    register_bless(app, exit_code);
    register_bisect(app, exit_code);
}

namespace {
std::string g_invocation = "iblcheck";
}
void set_invocation(const std::string& command_line) { g_invocation = command_line; }
const std::string& invocation() { return g_invocation; }

} // namespace iblcheck::cli
