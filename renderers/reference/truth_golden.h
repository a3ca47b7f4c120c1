// Writes one quadrature-truth golden: the EXR and its JSON sidecar, with the error bound (the two
// refinement levels' difference as relative RMSE, mean FLIP, per sphere and worst pixel) and issue
// 16's criterion verdict. Written by `iblcheck truth` (harness/cli/truth_command.cpp, which the
// regeneration script runs). Links the metrics (FLIP), which the integrator itself does not.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "renderers/reference/truth_renderer.h"
#include "renderers/reference/truth_sequence.h"

namespace iblcheck::truth {

inline constexpr double kCriterionFlip = 0.002;
inline constexpr double kCriterionRelativeRmse = 0.005;

struct GoldenRequest {
    TestSpec spec;       // method reference; the environment is loaded from spec.env
    std::string out_exr; // the golden; the sidecar is the same path with .json
    std::string command; // recorded as the regenerating command
    Progress progress;   // optional
};

struct GoldenWritten {
    nlohmann::json meta;  // the sidecar's content
    double mean_flip = 0; // between the two levels
    bool criterion_met = false;
};

GoldenWritten write_truth_golden(const GoldenRequest& request);

// The temporal truth as one golden: the frames stacked vertically in one EXR (frame f is rows f·H ..
// (f+1)·H − 1), the sidecar with the frame count and size, the accuracy, and the bound on the bound
// frames (relative RMSE, worst pixel, HDR-FLIP, and LDR-FLIP after the display transform — the temporal
// suite's own metric — each frame against its finer render). reference_sequence_key names it.
struct SequenceRequest {
    TestSpec spec; // scene, env (loaded from spec.env), options (frame is set per frame)
    int frames = 32;
    std::vector<int> bound_frames = {0, 16};
    std::string out_exr;
    std::string command;
    Progress progress;
};
nlohmann::json write_truth_sequence_golden(const SequenceRequest& request);

// A golden's EXR and its JSON sidecar (same path, .json), each through a temporary file renamed into
// place, the sidecar first; an EXR whose pixels are bit-identical to the new ones is not rewritten.
void write_golden_files(const std::string& exr_path, const cv::Mat& image, const nlohmann::json& meta);

// The environment as recorded in a sidecar: its stable name (environment_label: a built-in spec, a
// file's given name or file name; no absolute machine paths in goldens), beside the content hash that
// identifies it.
std::string portable_env_spec(const TestSpec& spec);

// The current UTC time as a sidecar records it (2026-11-23T09:24:43Z).
std::string utc_now();

// How far a new golden is from an older one (`iblcheck truth --compare OLD.exr`): mean HDR-FLIP with the
// old golden as the reference, and relative RMSE (monte_carlo.h's definition) over the new golden's
// covered pixels (the background is exactly 0).
struct GoldenDifference {
    double mean_flip = 0;
    double relative_rmse = 0;
};
GoldenDifference golden_difference(const std::string& new_exr, const std::string& old_exr);

} // namespace iblcheck::truth
