// Each subcommand registers itself on the CLI11 app and writes its exit code (errors.h) into
// `exit_code`. Exceptions derived from iblcheck::Error escaping a callback become exit 2 in main().
#pragma once
#include <CLI/CLI.hpp>

namespace iblcheck::cli {

void register_doctor_command(CLI::App& app, int& exit_code);
void register_list_command(CLI::App& app, int& exit_code);
void register_render_command(CLI::App& app, int& exit_code);
void register_run_commands(CLI::App& app, int& exit_code); // run, bless, bisect
void register_report_command(CLI::App& app, int& exit_code);
void register_truth_command(CLI::App& app, int& exit_code);   // truth_command.cpp
void register_explain_command(CLI::App& app, int& exit_code); // explain_command.cpp
void register_explore_command(CLI::App& app, int& exit_code); // explore_command.cpp

// The command line as typed, recorded in results JSON.
void set_invocation(const std::string& command_line);
const std::string& invocation();

} // namespace iblcheck::cli
