// The frames of temporal sequences on disk (issue 33). A temporal test renders three sequences (its
// own, the same scene with specular_aa=off, and the supersampled reference), 16 or 32 frames each;
// on the nightly of 2026-11-27 they were 49 s of a 116-s warm run, and none is timed. A sequence
// whose inputs did not change (a nightly after a change to the harness or the report, a second run)
// renders the same frames bit for bit, so its frames after the first are kept here.
//
// The first frame is always rendered again: the entry's name is a hash of what that render's
// provenance says of its inputs (the shader sources, a team's shading file included; the device
// and driver; the environment's content hash) with llvmpipe's CPU class, the spec but its frame
// index, the frame count and the renderer libraries' code (program.h: render_code_hash). And the
// entry is read only when its stored first frame equals the new one byte for byte, so a change the
// name misses still shows in frame 0 and makes the whole sequence render again. A damaged entry is
// a miss. IBLCHECK_SEQUENCE_CACHE=0 turns it off; =DIR puts it there (default: beside the SPIR-V
// cache, sequences/).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "kernel/program.h"
#include "renderers/render_api.h"

namespace iblcheck {

// Where entries go: $IBLCHECK_SEQUENCE_CACHE, else <SPIR-V cache's parent>/sequences; empty when off.
std::filesystem::path sequence_store_dir();

// Which sequence `frames` frames of `spec` are: every field of the spec but its frame index, and
// the count (the worker's sequences in memory and this store's names).
std::string sequence_spec_text(TestSpec spec, int frames);

// The entry's name for `frames` frames of `spec` whose first frame's render recorded `provenance`.
std::string sequence_store_key(const TestSpec& spec, int frames, const nlohmann::json& provenance,
                               const std::string& tool = render_code_hash());

// Every frame stored under `key` (the first one equal to `first`); none when there is no whole
// entry of `frames` frames, its first frame differs from `first`, or the store is off.
std::optional<std::vector<cv::Mat>> load_sequence(const std::string& key, const cv::Mat& first, int frames);

// Stores the frames (one size and type) under `key`; a failure to write is ignored (an optimisation).
void save_sequence(const std::string& key, const std::vector<cv::Mat>& frames);

} // namespace iblcheck
