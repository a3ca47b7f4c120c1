// The temporal truth (issue 16): a sequence of frames (option frame = 0..N−1) of a scene with moving
// normal detail (bumpy_sphere), each the quadrature truth — the pixel-footprint average of the full
// BRDF's shading, not the split sum — at TruthAccuracy::temporal(). The normal tables are built once for
// the whole sequence (the bumps only move which normals a pixel sees; truth_renderer.cpp caches them),
// so a frame costs its footprint integrals. The stated bound: `bound_frames` rendered again at the finer
// level, each frame's difference to its finer render (the same definition as a golden's bound).
#pragma once
#include <vector>

#include <opencv2/core.hpp>

#include "renderers/reference/quadrature/truth_renderer.h"

namespace iblcheck::truth {

struct TruthSequence {
    std::vector<cv::Mat> frames;    // CV_32FC3, linear
    std::vector<int> bound_frames;  // frames rendered again at the finer level
    std::vector<cv::Mat> finer;     // those frames at accuracy.finer()
    std::vector<TruthBound> bounds; // each bound frame against its finer render
    TruthAccuracy accuracy;
    int threads = 1;
    double seconds = 0;
};

// spec: scene, size, options (the frame option is set per frame; threads, env_rotation as render_truth).
// Throws UsageError for frames < 1 or a bound frame outside [0, frames).
TruthSequence render_truth_sequence(const TestSpec& spec, const Environment& env, int frames,
                                    const std::vector<int>& bound_frames, const Progress& progress = {});

} // namespace iblcheck::truth
