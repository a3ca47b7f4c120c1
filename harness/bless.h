// `iblcheck bless`: the only writer of baseline goldens. It re-renders the selected tests and
// writes each baseline with its provenance sidecar (scene, options, shader hash, driver, CPU,
// commit, date, accuracy against the truth, cost per pixel) atomically. A baseline whose pixels
// are bit-identical is left as it is (no git churn); its sidecar is rewritten only when a judged
// figure in it (accuracy, cost, size) changed.
#pragma once
#include <filesystem>
#include <optional>
#include <string>

#include "kernel/program.h"
#include "suite.h"

namespace iblcheck {

struct BlessOptions {
    std::string suite = "ci";
    std::string shader; // --shader: a team's shading file for every mobile test (suite.h)
    std::string filter;
    std::optional<std::string> label; // absent: the primary baseline; else baseline@LABEL
    std::filesystem::path goldens;
    std::string device;
    bool dry_run = false;
};

// Labels name files: [A-Za-z0-9._-]+ only (no '/', no empty label). Throws UsageError otherwise.
void check_label(const std::string& label);

// Re-renders and writes baselines; returns the exit code (2 if any render or write failed: nothing
// is written for a failed render).
int bless(const BlessOptions& options);

// The bless command that approves a test (shown on failure): the running binary as a person types
// it (program_name(): build/iblcheck after scripts/run.sh), so that it runs as printed. A sidecar
// records it with the portable "iblcheck" (no machine's paths in goldens).
std::string bless_command(const TestCase& t, const std::string& program = program_name());
class GoldenStore;
// The same, with --goldens ROOT when `store` is not the default one (a run with --goldens printed a
// bless command that wrote into goldens/).
std::string bless_command(const TestCase& t, const GoldenStore& store);

} // namespace iblcheck
