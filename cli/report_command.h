// `iblcheck report RESULTS.json... --out DIR [--junit FILE] [--history FILE]`: rebuilds the static HTML
// report from stored results (reports/report_writer.h); several results files, the shards of one run,
// are merged into DIR/results.json first (reports/merge_shards.h). Exit 0 when the report was written
// (whatever its verdicts: each shard's run gates), 2 on bad input or shards that are not one run.
#pragma once
#include <CLI/CLI.hpp>

namespace iblcheck::cli {

void register_report_command(CLI::App& app, int& exit_code);

} // namespace iblcheck::cli
