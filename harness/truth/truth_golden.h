// Writes one quadrature-truth golden: the EXR and its JSON sidecar, with the error bound (the two
// refinement levels' difference as relative RMSE, mean FLIP, per sphere and worst pixel) and issue
// 16's criterion verdict. Written by `iblcheck truth` (cli/truth_command.cpp, which the
// regeneration script runs). Links the metrics (FLIP), which the integrator itself does not.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "renderers/reference/quadrature/truth_renderer.h"
#include "renderers/reference/quadrature/truth_sequence.h"

namespace iblcheck::truth {

inline constexpr double kCriterionFlip = 0.002;
inline constexpr double kCriterionRelativeRmse = 0.005;

// The temporal truth's criterion (issue 28). The temporal suite scores each specular_aa variant by
// LDR-FLIP against this truth, 0.035 and more (off on sphere_field); its reference sequence is 0.0176
// from it. The sequence's own LDR-FLIP bound stays under 10 % of the smallest variant distance (0.002:
// 6 %; 11 % of the reference's): the criterion the suite relies on. The HDR-FLIP and relative-RMSE
// bounds are looser than the still goldens' (the sun's 1e5 reflection on bumpy_sphere under sky_sun,
// the rims of sphere_field's small spheres: CONVERGENCE.md "The temporal truth's criterion"); they are
// stated, recorded and required, but the suite never reads the sequences' HDR radiance.
inline constexpr double kSmallestJudgedLdrFlip = 0.035;
inline constexpr double kSequenceCriterionLdrFlip = 0.002;
inline constexpr double kSequenceCriterionFlip = 0.003;
inline constexpr double kSequenceCriterionRelativeRmse = 0.025;

// The sidecar's error_bound.criterion of a temporal sequence from its worst bound frame's figures:
// each bound with its `_met`, the still goldens' criterion with its verdict beside (for comparison),
// the justification, and `met` (all three sequence bounds hold).
nlohmann::json sequence_criterion(double worst_ldr_flip, double worst_flip, double worst_relative_rmse);

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

// The environment as recorded in a sidecar: its stable name (environment_label: a built-in spec, a
// file's given name or file name; no absolute machine paths in goldens), beside the content hash that
// identifies it.
std::string portable_env_spec(const TestSpec& spec);

// How far a new golden is from an older one (`iblcheck truth --compare OLD.exr`): mean HDR-FLIP with the
// old golden as the reference, and relative RMSE (monte_carlo.h's definition) over the new golden's
// covered pixels (the background is exactly 0).
struct GoldenDifference {
    double mean_flip = 0;
    double relative_rmse = 0;
};
GoldenDifference golden_difference(const std::string& new_exr, const std::string& old_exr);

} // namespace iblcheck::truth
