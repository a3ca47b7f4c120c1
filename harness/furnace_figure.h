// The white-furnace figure of a test's variant (issue 27): how much energy the variant's split sum
// gains or loses where the answer is known. Metal spheres with F0 = 1 (scene `furnace`, roughness
// 0, 0.25, 0.5, 0.75, 1) in a constant white environment reflect exactly their directional albedo;
// the truth holds it (goldens/reference/furnace__constant-1.exr). Each sphere's mean against the
// truth's, E/E_exact − 1, shows which variants are energy-faithful (measured, EnvBRDFApprox:
// −13.0 / −18.0 / −8.8 / +16.5 % at r = 0.25 / 0.5 / 0.75 / 1; the DFG LUT within 0.3 %), whatever
// scene the test renders.
#pragma once
#include <nlohmann/json.hpp>

#include "golden_store.h"
#include "suite.h"
#include "worker.h"

namespace iblcheck {

// {golden, roughness: [..], relative_error: [..], worst} for the mobile and sampled methods (the
// same options, minus those of the scene and the cube's size: in a constant environment any cube
// size is exact, so the render is a 320×64 one on a 16² cube); null for
// the reference method or when the store has no furnace truth.
nlohmann::json furnace_figure(const TestCase& tc, Worker& w, const GoldenStore& store);

} // namespace iblcheck
