// `iblcheck report RESULTS.json --out DIR [--history FILE]`: rebuilds the static HTML report from
// stored results (reports/report_writer.h). Exit 0 when the report was written, 2 on bad input.
#pragma once
#include <CLI/CLI.hpp>

namespace iblcheck::cli {

void register_report_command(CLI::App& app, int& exit_code);

} // namespace iblcheck::cli
