// The environment-dependent passes of the pipeline (done once per environment on a device):
// equirect → cube, its box pyramid, the GGX prefiltered chain, SH9, the DFG LUT and the
// irradiance cube. The mobile method uses all of them; the sampled peer the pyramid and SH9.
#pragma once
#include <string>
#include <vector>

#include "gpu_session.h"
#include "renderers/environments/environment.h"
#include "renderers/render_api.h"

namespace iblcheck {

struct PrecomputeSettings {
    uint32_t cube_size = 128;         // base size of the cubes (64–512)
    uint32_t mips = 0;                // levels of the prefiltered chain; 0: the full chain (mip_chain.h: chain_levels)
    uint32_t prefilter_samples = 256; // the prefilter's noise: < 1 % of the error against the truth (issue 27)
    std::string mip_mapping = "ue4";  // ue4 | filament | origin
    std::string storage = "rgba16f";  // rgba16f | rgba32f | rgbm8 | r11g11b10 | astc_hdr | astc_ldr_rgbm
    std::string astc_block = "4x4";   // storage=astc_*: 4x4 | 6x6
    float rgbm_range = 0.0f;          // storage=rgbm8|astc_ldr_rgbm: 0 = the source's peak (option rgbm_range=peak)
    std::string env_layout = "cube";  // cube | octahedral | equirect (env_layout.h)
    bool prefiltered = true;          // build the GGX chain (the sampled method does not need it)
    bool lut = false;                 // env_brdf=lut
    uint32_t lut_size = 64;
    uint32_t lut_samples = 512;
    bool irradiance_cube = false; // diffuse=irradiance_cube
    uint32_t irradiance_size = 32;
    float env_rotation_deg = 0;
};

struct IblResources {
    vk::Image source_cube;  // rgba32f, full box pyramid
    vk::Image prefiltered;  // storage format (ASTC: its decoded texels, RGBA16F), `mips` levels, env_layout
    vk::Buffer sh;          // 10 × vec4: SH9 of E/π, then the mean radiance
    vk::Image lut;          // rg16f (1×1 placeholder when unused)
    vk::Image irradiance;   // rgba32f cube (1×1 placeholder when unused)
    uint32_t full_mips = 0; // log2(cube_size) + 1: the source pyramid's levels
    uint32_t levels = 0;    // the prefiltered chain's levels (mip_chain.h: chain_levels)
    bool native_r11g11b10 = false;
    // The prefiltered chain as a device would store it: texels (borders of 2D layouts included)
    // and bytes in the storage format (ASTC: its blocks; r11g11b10: 4 bytes a texel even where
    // lavapipe holds it in RGBA16F).
    uint64_t texel_count = 0;
    uint64_t texture_bytes = 0;
    // RGBM storage: the range the chain was encoded with, and the share of the base level's
    // radiant energy above it (what the clamp to the range loses in the sharpest level).
    float rgbm_range = 0;
    double rgbm_clipped_energy = 0;
};

// Bytes of one w×h level of `layers` layers in the storage format.
uint64_t storage_level_bytes(const std::string& storage, const std::string& astc_block, uint32_t width, uint32_t height,
                             uint32_t layers);

// Records and runs the precompute passes; appends their GPU timings (precompute = true).
IblResources run_precompute(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                            std::vector<PassTiming>& timings);

// run_precompute through the session's cache: the same environment and settings reuse the device
// resources; `timings` receives the passes' timings as first measured (they are the cost of the
// precompute, whether or not this render paid it). Sets `cached` when reused.
// What identifies a precompute's result: the environment (`env_id`: its content hash, or for
// grouping before anything is loaded its spec) and every setting.
std::string precompute_key(const std::string& env_id, const PrecomputeSettings& s);

// The settings of the radiance chain `s` is derived from: the source cube's pyramid, its SH9 and the
// GGX-prefiltered chain in rgba32f, which every variant differing from `s` only in storage, the DFG
// table or the irradiance cube shares (run_precompute computes it once per session and encodes it;
// encode_storage.comp). precompute_key(env, chain_settings(s)) names it.
PrecomputeSettings chain_settings(const PrecomputeSettings& s);

std::shared_ptr<IblResources> precompute_cached(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                                                std::vector<PassTiming>& timings, bool& cached);

// The defines of the passes that read or write the prefiltered chain: the option table's for
// storage, mip_mapping and env_layout (storage.glsl, mip_mapping.glsl, env_layout.glsl), plus the
// RGBM range the chain was encoded with (r.rgbm_range) and whether R11G11B10 is stored natively.
vk::Defines storage_defines(const PrecomputeSettings& s, const IblResources& r);

} // namespace iblcheck
