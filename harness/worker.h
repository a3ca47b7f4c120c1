// One runner thread's renderer and what it keeps between tests: the GPU session (pipelines,
// precomputed IBL) and the tone-mapped frames of sequences already rendered (the reference and
// `off` sequences are shared by every specular-AA variant of a scene).
#pragma once
#include <array>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "renderers/renderer.h"

namespace iblcheck {

struct Worker {
    explicit Worker(const std::string& device);
    Renderer renderer;
    std::string device;
    std::map<std::string, std::vector<cv::Mat>> sequences;
    // Scores (flicker, variation ratio, mean FLIP) of one held sequence against another, by their
    // addresses in `sequences` (never erased, so an address names one sequence for the worker's
    // life): every specular-AA variant scores the same `off` sequence against the same reference.
    std::map<std::pair<const void*, const void*>, std::array<double, 3>> sequence_scores;
    // Whether frames after the first may come from the sequence store (sequence_store.h); `run
    // --repeat` renders them all again, since it looks for renders that change between runs.
    bool stored_sequences = true;

    // The display-transformed frames 0..frames-1 of `spec` (cached). Throws InputError naming the
    // frame when one has non-finite pixels.
    const std::vector<cv::Mat>& sequence(TestSpec spec, int frames);
};

} // namespace iblcheck
