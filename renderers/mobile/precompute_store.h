// The precompute passes' results on disk (issue 33): the ci suite spent more than half its time
// prefiltering the same environments again in every run. An entry holds every image and figure of
// IblResources, byte for byte as the passes wrote them, so a render from it is bit-identical.
// Its name is a hash of every input: the environment's pixels (content hash), every setting, the
// sources of the passes' shaders and what they include, the device and driver (Mesa, LLVM) and
// llvmpipe's CPU class (its generated code can round differently), and the renderer libraries' code
// (program.h: render_code_hash; a build with other renderer code or another libastcenc misses). A
// changed input is a miss, and a damaged entry is computed again. IBLCHECK_PRECOMPUTE_CACHE=0 turns
// it off; =DIR puts it there.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ibl_precompute.h"
#include "kernel/program.h"

namespace iblcheck {

// Where entries go: $IBLCHECK_PRECOMPUTE_CACHE, else $IBLCHECK_CACHE_DIR/precompute (default
// .cache/precompute); empty when off.
std::filesystem::path precompute_store_dir();

// The entry's name: a hash over every input (see above).
// `tool`: the C++ that computes it (program.h: render_code_hash, the renderer libraries of the build),
// so an entry a build with other renderer code wrote (a bisect step across such a change) is a miss.
std::string precompute_store_key(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                                 const std::string& tool = render_code_hash());

// The resources stored under `key` on this device, and the timings they were first made with; none
// when there is no whole entry (a damaged one is ignored).
std::optional<IblResources> load_precompute(vk::Context& ctx, const std::string& key, std::vector<PassTiming>& timings);

// Stores `r` under `key` (atomically: a temporary file renamed); a failure to write is ignored (the
// cache is an optimisation).
void save_precompute(vk::Context& ctx, const std::string& key, const IblResources& r, const std::vector<PassTiming>& timings);

} // namespace iblcheck
