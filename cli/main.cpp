// iblcheck: image-diff validation harness for mobile IBL shaders.
// Exit codes (docs/DESIGN.md): 0 pass, 1 regression, 2 usage/input/environment error,
// 125 (bisect only) cannot test this commit.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string_view>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli/store_folders.h"
#include "cli/version.h"
#include "commands.h"
#include "compare_command.h"
#include "kernel/errors.h"
#include "kernel/program.h"
#include "kernel/shell_quote.h"
#include "kernel/store_budget.h"
#include "kernel/store_entry.h"

namespace {

// Help and the version read no store: a bad budget in the environment does not hide them.
bool asks_for_help(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        if (a == "-h" || a == "--help" || a == "--version") return true;
    }
    return false;
}

// After a command that wrote store entries: the least recently used go until the stores fit their
// budget (store_budget.h). This command's own entries stay. The stores are an optimisation, so a
// failure here changes no exit code.
void keep_stores_in_budget(std::uintmax_t budget, std::filesystem::file_time_type started) {
    if (!iblcheck::store_entries_written()) return;
    try {
        // A write's time comes from the kernel's coarse clock (a few ms behind the fine one).
        iblcheck::prune_stores(iblcheck::cli::store_folders(), budget, started - std::chrono::seconds(2));
    } catch (const std::exception& e) {
        fmt::print(stderr, "warning: the stores were not pruned: {}\n", e.what());
    }
}

int run_command_line(int argc, char** argv, std::uintmax_t& budget) {
    CLI::App app{"iblcheck — image-diff validation harness for mobile IBL shaders"};
    app.require_subcommand(1);
    app.set_version_flag("--version", iblcheck::cli::version_string(), "Print the version, commit, compiler and build type");
    int exit_code = iblcheck::kExitPass;
    iblcheck::cli::register_doctor_command(app, exit_code);
    iblcheck::cli::register_list_command(app, exit_code);
    iblcheck::cli::register_render_command(app, exit_code);
    iblcheck::register_compare_command(app, exit_code);
    iblcheck::cli::register_run_commands(app, exit_code);
    iblcheck::cli::register_report_command(app, exit_code);
    iblcheck::cli::register_truth_command(app, exit_code);
    // The printed bless and truth commands name this binary as the user reaches it (program.h).
    iblcheck::set_program_name(iblcheck::program_from_self());
    iblcheck::cli::register_explain_command(app, exit_code);
    iblcheck::cli::register_explore_command(app, exit_code);
    {
        std::string line = iblcheck::program_name();
        for (int i = 1; i < argc; ++i) line += " " + iblcheck::shell_arg(argv[i]); // the report's Copy button pastes it
        iblcheck::cli::set_invocation(line);
    }
    // `git bisect run` takes 2 as "bad": anything a bisect step cannot run is 125 (skip).
    const bool bisect = argc > 1 && std::string(argv[1]) == "bisect";
    try {
        if (!asks_for_help(argc, argv)) budget = iblcheck::store_budget_bytes(); // a bad value stops here, before any work
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int rc = app.exit(e);
        return rc == 0 ? 0 : bisect ? iblcheck::kExitCannotTest : iblcheck::kExitError;
    } catch (const iblcheck::ShaderCompileError& e) {
        fmt::print(stderr, "error: shader compile failed:\n{}\n", e.what());
        return iblcheck::kExitError;
    } catch (const iblcheck::Error& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return bisect ? iblcheck::kExitCannotTest : iblcheck::kExitError;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: internal: {}\n", e.what());
        return bisect ? iblcheck::kExitCannotTest : iblcheck::kExitError;
    }
    return exit_code;
}

} // namespace

int main(int argc, char** argv) {
    try {
        const auto started = std::filesystem::file_time_type::clock::now();
        std::uintmax_t budget = 0;
        const int rc = run_command_line(argc, argv, budget);
        if (budget) keep_stores_in_budget(budget, started);
        return rc;
    } catch (...) { // what the command's own handlers did not catch (setting up the command line)
        std::fputs("error: internal: an unexpected exception\n", stderr);
        return iblcheck::kExitError;
    }
}
