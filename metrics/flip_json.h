// A FLIP result as JSON: the keys results.json's "flip" object and `iblcheck compare --json` share
// (results/RESULTS_FORMAT.md), written in one place so the two cannot drift apart.
#pragma once
#include <nlohmann/json.hpp>

#include "metrics/flip.h"

namespace iblcheck {

// mean, weighted_median, weighted_q1, weighted_q3, p99, min, max, block_max, block_x, block_y and
// mode; for an HDR result (mode "hdr") also start_exposure, stop_exposure, num_exposures and
// exposure_source. The error map is not included.
nlohmann::json flip_json(const FlipResult& r);

} // namespace iblcheck
