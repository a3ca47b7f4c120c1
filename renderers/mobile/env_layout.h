// Layout of the prefiltered radiance (option env_layout): the cubemap, or one 2D texture — the
// octahedral map or the lat-long (equirect) — which seed 001 proposes so instances can share a
// texture array (GLES 3.1 has no cube arrays). The GLSL is renderers/shaders/env_layout.glsl; this
// is its host side: sizes, texel counts and bytes, and the same mappings on the CPU for tests and
// for the texel solid angles.
//
// 2D layouts, per mip level w×h: a 1-texel border (gutter) around an inner (w−2)×(h−2) map, so
// bilinear filtering never reads across a seam. A border texel holds exactly the inner texel on
// the other side of the seam it continues (gutter_source): octahedral — the square's edges fold
// onto themselves (mirror about each edge's midpoint; corners onto the opposite corner);
// equirect — longitude wraps, and a row beyond a pole is the pole row half a turn around. Each
// level's map is inset by its own border, so a lookup samples two integer levels with their own
// UVs and blends them (what hardware trilinear does across levels; layout_uv()).
#pragma once
#include <array>
#include <cstdint>
#include <string>

namespace iblcheck {

enum class EnvLayout { cube, octahedral, equirect };

EnvLayout env_layout_from_option(const std::string& value); // UsageError for anything else

// Base extent of the prefiltered texture for a cube of `cube_size`: cube N×N×6; octahedral
// 2N×2N (4N² texels, 2/3 of the cube's 6N²); equirect 4N×2N (8N², 4/3 of the cube's: the ~30 %
// more texels seed 001 measures for lat-long at matched resolution).
struct LayoutExtent {
    uint32_t width = 0, height = 0, layers = 1;
};
LayoutExtent layout_extent(EnvLayout layout, uint32_t cube_size);

// Texels of the whole `mips`-level chain (borders included).
uint64_t layout_texel_count(EnvLayout layout, uint32_t cube_size, uint32_t mips);

// Throws UsageError when the chain's last level has no inner texel left inside its border (a 2D
// layout needs at least 3 texels a side at every stored level).
void check_layout_mips(EnvLayout layout, uint32_t cube_size, uint32_t mips);

using Dir = std::array<double, 3>;
using Uv = std::array<double, 2>;

// Octahedral map (Praun & Hoppe 2003; the form of Cigolle et al. 2014, "A Survey of Efficient
// Representations for Independent Unit Vectors", listing 1): +Z at the centre, −Z at the corners.
Uv octahedral_encode(const Dir& d);  // unit d → [0, 1]²
Dir octahedral_decode(const Uv& uv); // [0, 1]² → unit direction
// Lat-long, the environment's own convention (environment.h): u = 0.5 + atan2(x, −z)/2π, v = acos(y)/π.
Uv equirect_encode(const Dir& d);
Dir equirect_decode(const Uv& uv);

// The inner texel (0..n−1 each way) that border texel `j` (−1..n each way) copies; inner texels
// map to themselves.
std::array<int, 2> gutter_source(EnvLayout layout, std::array<int, 2> j, std::array<int, 2> inner);

// Direction at the centre of texel (x, y) of a w×h level (border texels: of the texel they copy).
Dir layout_texel_direction(EnvLayout layout, uint32_t x, uint32_t y, uint32_t w, uint32_t h);

// Solid angle of inner texel (x, y) (x, y ≥ 1, < w−1 / h−1) of a w×h level, by `n`×`n`
// midpoint sub-samples of the mapping's Jacobian (|∂d/∂u × ∂d/∂v| du dv).
double layout_texel_solid_angle(EnvLayout layout, uint32_t x, uint32_t y, uint32_t w, uint32_t h, int n = 4);

} // namespace iblcheck
