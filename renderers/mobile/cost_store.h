// The instruction-counting twin's result on disk (issue 33): a warm ci run spent a quarter of its
// worker time rendering every test a second time, instrumented, for a count that depends only on
// what the pass computes with. An entry holds the count (instructions per pixel, as its double's
// bits) under a hash of every input: the counted SPIR-V's source hash (shader sources, includes,
// defines, options, a team's ibl_shade file, the counting pass's version), the push constants
// (size, ssaa, options), the draw's shape, the content of what the pass reads (the environment's
// precompute, keyed as precompute_store.h keys it, and the scene), the device and driver, llvmpipe's
// CPU class, the renderer libraries' code (program.h: render_code_hash; the counting pass's host side
// is C++), and the timed pass's output image: the stored count was checked against an image equal
// to it bit for bit. A changed input is a miss; a damaged entry is counted again.
// IBLCHECK_COST_CACHE=0 turns it off; =DIR puts it there (default: beside the SPIR-V cache, cost/).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gpu_session.h"
#include "ibl_precompute.h"
#include "kernel/program.h"

namespace iblcheck {

// Where entries go: $IBLCHECK_COST_CACHE, else <SPIR-V cache's parent>/cost; empty when off.
std::filesystem::path cost_store_dir();

// A content hash of what a shading pass reads besides its shader and push constants: the
// environment's precompute (its store key: pixels, settings, pass shaders, driver, CPU class) and
// the scene buffer's bytes.
std::string shading_inputs_hash(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                                const vk::Buffer& scene_buf);

// The entry's name: a hash of `parts` (the pass's inputs), the device, driver and CPU class.
// `tool`: the C++ that counts (program.h: render_code_hash, the renderer libraries of the build): the
// counting pass's host side is C++.
std::string cost_store_key(GpuSession& gpu, const std::vector<std::string>& parts, const std::string& tool = render_code_hash());

// A content hash of `n` bytes (push constants, output images) for a key part.
std::string bytes_hash(const void* data, size_t n);

// The count stored under `key`; none when there is none, the store is off or the entry is damaged.
std::optional<double> load_cost(const std::string& key);

// Stores `instructions_per_pixel` under `key` (a temporary file renamed); a failure to write is
// ignored (the store is an optimisation).
void save_cost(const std::string& key, double instructions_per_pixel);

} // namespace iblcheck
