// Provenance shared by goldens and runs: which commit, when, on what platform, and what the
// render cost. A golden's sidecar holds these so a verdict can say what differs between the
// machine that blessed it and this one.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "renderers/render_api.h"

namespace iblcheck {

// {"commit": "<12 hex>[-dirty]", "date": ISO-8601 UTC, "cpu_features": [...], "cpu_class": "..."}
nlohmann::json run_provenance();

// The render's deterministic cost per pixel: {"texture_fetches_per_pixel": F[,
// "spirv_instructions_per_pixel": I]} (costs a GPU method measured; empty for the CPU reference).
nlohmann::json render_cost(const RenderResult& r);

// "" when the golden was blessed on this platform; otherwise what differs, e.g. "golden blessed
// with Mesa 22.3.6 (LLVM 15.0.6) on CPU class avx2-fma-f16c-256; this run: ... sse4.1-128".
std::string platform_difference(const nlohmann::json& golden_provenance, const nlohmann::json& render_provenance,
                                const std::string& this_cpu_class);

// llvmpipe's CPU class on this machine (GALLIUM_OVERRIDE_CPU_CAPS and LP_NATIVE_VECTOR_WIDTH included).
std::string this_cpu_class();

} // namespace iblcheck
