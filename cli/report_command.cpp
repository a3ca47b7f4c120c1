#include "cli/report_command.h"

#include <filesystem>

#include <fmt/core.h>

#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/output_files.h"
#include "reports/merge_shards.h"
#include "reports/nightly_findings.h"
#include "reports/report_writer.h"
#include "results/junit.h"

namespace iblcheck::cli {

namespace {
// The report overwrites index.html, data/ and the images in --out: a folder that holds files is
// written into only with --force (the run's own folder included: rebuilding a report in place).
void check_report_folder(const std::filesystem::path& out, bool force) {
    std::error_code ec;
    if (force || !std::filesystem::exists(out, ec)) return;
    if (!std::filesystem::is_directory(out, ec)) throw UsageError("--out " + out.string() + ": exists and is not a folder");
    if (!std::filesystem::is_empty(out, ec))
        throw UsageError("--out " + out.string() + ": holds files (an earlier report?); pass --force to write over them");
}
// The folder a results file names its images from.
std::filesystem::path folder_of(const std::filesystem::path& results_file) {
    return results_file.parent_path().empty() ? std::filesystem::path(".") : results_file.parent_path();
}

// Several shards: merged (reports/merge_shards.h) into --out, with each shard's images copied beside the
// merged results.json (a test's images are under images/<test>/, so the shards' never collide; the
// shared truth images are the same file in every shard).
nlohmann::json merge_into(const std::vector<std::string>& files, const std::filesystem::path& out) {
    namespace fs = std::filesystem;
    std::vector<report::Shard> shards;
    for (const std::string& f : files) shards.push_back({f, report::read_results(f)});
    nlohmann::json merged = report::merge_shards(shards);
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec) throw InputError(out.string() + ": cannot create the report folder: " + ec.message());
    for (const report::Shard& s : shards) {
        const fs::path images = folder_of(s.file) / "images";
        if (!fs::is_directory(images)) continue;
        fs::copy(images, out / "images", fs::copy_options::recursive | fs::copy_options::skip_existing, ec);
        if (ec) throw InputError(images.string() + ": cannot copy into " + (out / "images").string() + ": " + ec.message());
    }
    write_file_atomically(out / "results.json", merged.dump(1) + "\n", "merged results JSON");
    return merged;
}
} // namespace

void register_report_command(CLI::App& app, int& exit_code) {
    struct Args {
        std::vector<std::string> results;
        std::string out, history, junit;
        std::vector<std::string> findings;
        bool force = false;
    };
    auto args = std::make_shared<Args>();
    auto* cmd = app.add_subcommand("report", "Rebuild the static HTML report from stored results JSON; several results "
                                             "files (the shards of one run) are merged into one report");
    cmd->add_option("results", args->results,
                    "results.json written by `iblcheck run`; several: the shards of one run (`run --shard i/n`), "
                    "merged (same suite and commit, every shard once) into --out/results.json")
        ->required();
    cmd->add_option("--out", args->out, "folder for index.html and the images it shows")->required();
    cmd->add_option("--junit", args->junit, "also write JUnit XML of the (merged) results");
    cmd->add_option("--history", args->history, "history file (JSON lines, one entry per run) for trend lines");
    cmd->add_option("--findings", args->findings,
                    "an `iblcheck explain/explore --json` file for the findings at the top (repeatable)");
    cmd->add_flag("--force", args->force,
                  "write into an --out folder that holds files (index.html and images are overwritten), and over --junit");
    cmd->callback([args, &exit_code] {
        namespace fs = std::filesystem;
        check_report_folder(args->out, args->force);
        check_output_file(args->junit, "--junit", args->force, {});
        const bool merge = args->results.size() > 1;
        const nlohmann::json results =
            merge ? merge_into(args->results, args->out) : report::read_results(fs::path(args->results[0]));
        std::vector<nlohmann::json> history, findings;
        if (!args->history.empty()) history = report::read_history(args->history);
        for (const std::string& f : args->findings) findings.push_back(report::read_findings(f));
        const fs::path dir = merge ? fs::path(args->out) : folder_of(args->results[0]);
        report::write_report(results, dir, args->out, history, findings);
        if (!args->junit.empty()) write_junit(results, args->junit);
        fmt::print("report: {}{}\n", (fs::path(args->out) / "index.html").string(),
                   merge ? fmt::format(" ({} shards merged: {} tests)", args->results.size(), results["tests"].size()) : "");
        exit_code = kExitPass;
    });
}

} // namespace iblcheck::cli
