#include "mip_chain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kernel/errors.h"

namespace iblcheck {

namespace {

// mip_mapping.glsl's constants: UE4 ReflectionEnvironmentShared.ush, and the origin curve's k.
constexpr double kRoughestMip = 1.0, kRoughnessMipScale = 1.2, kOriginK = 32.0;
// r = 1 up to the rounding of exp2(log2(x)).
constexpr double kRoughest = 1.0 - 1e-9;

enum class Curve { ue4, filament, origin };

Curve curve_of(const std::string& mip_mapping) {
    if (mip_mapping == "ue4") return Curve::ue4;
    if (mip_mapping == "filament") return Curve::filament;
    if (mip_mapping == "origin") return Curve::origin;
    throw UsageError("option 'mip_mapping': unknown value '" + mip_mapping + "'; valid: ue4, filament, origin");
}

const char* layout_option_name(EnvLayout layout) {
    return layout == EnvLayout::cube ? "cube" : layout == EnvLayout::octahedral ? "octahedral" : "equirect";
}

} // namespace

uint32_t cubemap_max_mip(uint32_t cube_size) { return uint32_t(std::lround(std::log2(double(std::max(1u, cube_size))))); }

uint32_t layout_full_mips(EnvLayout layout, uint32_t cube_size) {
    const uint32_t full = cubemap_max_mip(cube_size) + 1;
    if (layout == EnvLayout::cube) return full;
    const LayoutExtent e = layout_extent(layout, cube_size);
    uint32_t mips = 1;
    while (std::min(e.width, e.height) >> mips >= 3) ++mips;
    return mips;
}

double chain_level_roughness(const std::string& mip_mapping, double lod, uint32_t cube_size, uint32_t levels) {
    const double max_mip = cubemap_max_mip(cube_size), max_lod = double(levels) - 1.0;
    double r = 0;
    switch (curve_of(mip_mapping)) {
    case Curve::ue4: r = std::exp2((kRoughestMip - (max_mip - 1.0 - lod)) / kRoughnessMipScale); break;
    case Curve::filament: r = max_lod > 0 ? 1.0 - std::sqrt(std::max(0.0, 1.0 - lod / max_lod)) : 0.0; break;
    case Curve::origin: r = max_lod > 0 ? (std::exp2(lod / max_lod * std::log2(1.0 + kOriginK)) - 1.0) / kOriginK : 0.0; break;
    }
    return std::clamp(r, 0.0, 1.0);
}

double chain_roughness_lod(const std::string& mip_mapping, double roughness, uint32_t cube_size, uint32_t levels) {
    const double max_mip = cubemap_max_mip(cube_size), max_lod = double(levels) - 1.0;
    double lod = 0;
    switch (curve_of(mip_mapping)) {
    case Curve::ue4: lod = max_mip - 1.0 - (kRoughestMip - kRoughnessMipScale * std::log2(std::max(roughness, 1e-6))); break;
    case Curve::filament: lod = max_lod * roughness * (2.0 - roughness); break;
    case Curve::origin: lod = max_lod * std::log2(1.0 + kOriginK * roughness) / std::log2(1.0 + kOriginK); break;
    }
    return std::clamp(lod, 0.0, std::max(0.0, max_lod));
}

uint32_t chain_levels(const std::string& mip_mapping, EnvLayout layout, uint32_t cube_size, uint32_t requested) {
    const uint32_t full = layout_full_mips(layout, cube_size);
    const uint32_t levels = requested == 0 ? full : requested;
    // The first level whose curve value is r = 1 (UE4: log2(size) − 2; filament and origin: the last).
    uint32_t needed = 2;
    while (needed <= full && chain_level_roughness(mip_mapping, double(needed - 1), cube_size, needed) < kRoughest) ++needed;
    if (levels >= 2 && levels <= full && chain_level_roughness(mip_mapping, double(levels - 1), cube_size, levels) >= kRoughest)
        return levels;
    char end[96];
    if (levels > full)
        std::snprintf(end, sizeof end, "exceed the %u it can hold", full);
    else
        std::snprintf(end, sizeof end, "end at roughness %.3f, not 1",
                      levels >= 1 ? chain_level_roughness(mip_mapping, double(levels - 1), cube_size, levels) : 0.0);
    throw UsageError("option 'mips': " + std::to_string(levels) + " levels of a " + std::to_string(cube_size) +
                     " cube (env_layout=" + layout_option_name(layout) + ") " + end + "; mip_mapping=" + mip_mapping + " needs " +
                     std::to_string(needed) + " to " + std::to_string(full) + " levels (leave mips out for the full chain, " +
                     std::to_string(full) + ")");
}

} // namespace iblcheck
