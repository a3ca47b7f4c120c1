// iblcheck: image-diff validation harness for mobile IBL shaders.
// Exit codes (docs/DESIGN.md): 0 pass, 1 regression, 2 usage/input/environment error,
// 125 (bisect only) cannot test this commit.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "cli/version.h"
#include "commands.h"
#include "compare_command.h"
#include "kernel/errors.h"
#include "kernel/program.h"
#include "kernel/shell_quote.h"

int main(int argc, char** argv) {
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
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int rc = app.exit(e);
        // `git bisect run` takes 2 as "bad": a bisect command line it cannot parse is 125 (skip).
        const bool bisect = argc > 1 && std::string(argv[1]) == "bisect";
        return rc == 0 ? 0 : bisect ? iblcheck::kExitCannotTest : iblcheck::kExitError;
    } catch (const iblcheck::ShaderCompileError& e) {
        fmt::print(stderr, "error: shader compile failed:\n{}\n", e.what());
        return iblcheck::kExitError;
    } catch (const iblcheck::Error& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return iblcheck::kExitError;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: internal: {}\n", e.what());
        return iblcheck::kExitError;
    }
    return exit_code;
}
