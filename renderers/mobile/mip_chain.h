// The prefiltered chain on the host: how many levels it has and which roughness each holds. The
// mapping is renderers/shaders/mip_mapping.glsl's (the prefilter writes level m at
// lod_to_roughness(m), the shading reads at roughness_to_lod(r)), written again here for the
// checks made before any GPU work, the provenance and the tests.
#pragma once
#include <cstdint>
#include <string>

#include "env_layout.h"

namespace iblcheck {

// log2(cube_size): the last mip index of the full chain down to 1×1. UE4 passes this as
// CubemapMaxMip (FloorLog2 of the capture size), not the mip count.
uint32_t cubemap_max_mip(uint32_t cube_size);

// The most levels the layout holds: cube log2(cube_size) + 1 (down to 1×1); a 2D layout down to
// its last level with an inner texel inside the border (env_layout.h: check_layout_mips).
uint32_t layout_full_mips(EnvLayout layout, uint32_t cube_size);

// mip_mapping.glsl's lod_to_roughness and roughness_to_lod for a chain of `levels` levels of a
// `cube_size` cube (mip_mapping: ue4 | filament | origin; anything else is a UsageError).
double chain_level_roughness(const std::string& mip_mapping, double lod, uint32_t cube_size, uint32_t levels);
double chain_roughness_lod(const std::string& mip_mapping, double roughness, uint32_t cube_size, uint32_t levels);

// The chain's length: `requested` levels (option mips), or the layout's full chain when 0. A chain
// whose roughest level holds r < 1 (UE4's curve reaches r = 1 only at mip log2(size) − 2, so a
// fixed count truncates larger cubes) or that cannot hold both ends (one level) is a UsageError
// naming the count that would do: rough spheres would otherwise read a level sharper than their
// lobe and the accuracy would depend on the cube size for a reason no engine has.
uint32_t chain_levels(const std::string& mip_mapping, EnvLayout layout, uint32_t cube_size, uint32_t requested);

} // namespace iblcheck
