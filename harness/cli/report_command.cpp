#include "harness/cli/report_command.h"

#include <filesystem>

#include <fmt/core.h>

#include "harness/common/errors.h"
#include "reports/report_writer.h"

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
} // namespace

void register_report_command(CLI::App& app, int& exit_code) {
    struct Args {
        std::string results, out, history;
        bool force = false;
    };
    auto args = std::make_shared<Args>();
    auto* cmd = app.add_subcommand("report", "Rebuild the static HTML report from a stored results JSON");
    cmd->add_option("results", args->results, "results.json written by `iblcheck run`")->required();
    cmd->add_option("--out", args->out, "folder for index.html and the images it shows")->required();
    cmd->add_option("--history", args->history, "history file (JSON lines, one entry per run) for trend lines");
    cmd->add_flag("--force", args->force, "write into an --out folder that holds files (index.html and images are overwritten)");
    cmd->callback([args, &exit_code] {
        namespace fs = std::filesystem;
        const fs::path results_file(args->results);
        check_report_folder(args->out, args->force);
        const nlohmann::json results = report::read_results(results_file);
        std::vector<nlohmann::json> history;
        if (!args->history.empty()) history = report::read_history(args->history);
        fs::path dir = results_file.parent_path();
        if (dir.empty()) dir = ".";
        report::write_report(results, dir, args->out, history);
        fmt::print("report: {}\n", (fs::path(args->out) / "index.html").string());
        exit_code = kExitPass;
    });
}

} // namespace iblcheck::cli
