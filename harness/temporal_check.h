// Temporal tests (suite.h, TemporalSpec): the test's frame sequence, the same scene with
// specular_aa=off and the supersampled reference sequence, scored for flicker and FLIP; each
// configured bound is a Check (verdict.h).
#pragma once
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "suite.h"
#include "verdict.h"
#include "worker.h"

namespace iblcheck {

struct TemporalOutcome {
    nlohmann::json json;          // the test's "temporal" results object
    std::vector<Check> checks;
};

// Writes the frames as PNGs under img_dir (when not empty); `rel_dir` is how results name that folder.
TemporalOutcome run_temporal(const TestCase& tc, Worker& w, const std::filesystem::path& img_dir,
                             const std::string& rel_dir, int flip_threads);

} // namespace iblcheck
