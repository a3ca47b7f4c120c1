// Writes one Monte Carlo golden (`iblcheck truth --integrator monte_carlo`): the seed-K render of the
// Monte Carlo integrator (monte_carlo.h) as the EXR, and a JSON sidecar with its noise floor against a
// second render with seed K + 1 (relative RMSE and mean FLIP between the two, issue 5's criterion with its
// verdict), the provenance of the seed-K render, and the spec. The near-mirror golden is made this way
// (the quadrature refuses lobes with α < 2e-3 on smooth spheres). Links the metrics (FLIP).
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "renderers/option_table.h"
#include "renderers/reference/monte_carlo/monte_carlo.h"

namespace iblcheck::reference {

struct MonteCarloGoldenRequest {
    TestSpec spec; // scene, env (loaded from spec.env), options (material, threads, ...)
    int spp = option_int(OptionMap{}, "spp", "reference");
    int seed = 0;        // the golden's lighting seed; the noise floor's second render uses seed + 1
    std::string out_exr; // the golden; the sidecar is the same path with .json
    std::string command; // recorded as the regenerating command
};

struct MonteCarloGoldenWritten {
    nlohmann::json meta; // the sidecar's content
    NoiseFloor noise;    // both renders and their comparison
    cv::Mat flip_errmap; // HDR-FLIP between the two renders (seed K as the reference)
    bool criterion_met = false;
};

MonteCarloGoldenWritten write_monte_carlo_golden(const MonteCarloGoldenRequest& request);

// The noise floor by WxH tile (48x48: one sphere of the roughness sweep), to see where the noise is:
// one line per tile row ("mean FLIP/relative RMSE" per tile), then fully vs partially covered pixels.
std::string noise_floor_by_tile(const MonteCarloGoldenWritten& golden, int tile_w, int tile_h);

} // namespace iblcheck::reference
