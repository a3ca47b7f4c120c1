// Temporal tests (suite.h, TemporalSpec): the test's frame sequence, the same scene with
// specular_aa=off and the supersampled reference sequence (the method itself without aliasing),
// scored for flicker and FLIP; and, when the golden store holds the scene's temporal truth
// (reference/<key>__frames=N.exr: the quadrature truth of every frame, full BRDF and exact pixel
// footprint), both sequences scored against it too ("truth"; checks truth_flicker, truth_flip_mean,
// truth_flip_ratio). Each configured bound is a Check (verdict.h); a truth check without the truth
// golden cannot judge: an InputError naming the golden (exit 2, bisect 125).
#pragma once
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "golden_store.h"
#include "suite.h"
#include "verdict.h"
#include "worker.h"

namespace iblcheck {

struct TemporalOutcome {
    nlohmann::json json; // the test's "temporal" results object
    std::vector<Check> checks;
};

// Writes the frames as PNGs under img_dir (when not empty); `rel_dir` is how results name that folder.
TemporalOutcome run_temporal(const TestCase& tc, Worker& w, const GoldenStore& store, const std::filesystem::path& img_dir,
                             const std::string& rel_dir, int flip_threads);

} // namespace iblcheck
