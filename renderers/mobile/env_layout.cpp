#include "env_layout.h"

#include <algorithm>
#include <cmath>

#include "kernel/errors.h"

namespace iblcheck {

namespace {
constexpr double kPi = 3.14159265358979323846;
double sign_nz(double x) { return x >= 0 ? 1.0 : -1.0; }
Dir normalized(Dir d) {
    double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return {d[0] / l, d[1] / l, d[2] / l};
}
const char* layout_name(EnvLayout l) {
    return l == EnvLayout::cube ? "cube" : l == EnvLayout::octahedral ? "octahedral" : "equirect";
}
} // namespace

EnvLayout env_layout_from_option(const std::string& value) {
    if (value == "cube") return EnvLayout::cube;
    if (value == "octahedral") return EnvLayout::octahedral;
    if (value == "equirect") return EnvLayout::equirect;
    throw UsageError("option 'env_layout': unknown value '" + value + "'; valid: cube, octahedral, equirect");
}

LayoutExtent layout_extent(EnvLayout layout, uint32_t n) {
    switch (layout) {
    case EnvLayout::cube: return {n, n, 6};
    case EnvLayout::octahedral: return {2 * n, 2 * n, 1};
    case EnvLayout::equirect: return {4 * n, 2 * n, 1};
    }
    return {};
}

uint64_t layout_texel_count(EnvLayout layout, uint32_t cube_size, uint32_t mips) {
    LayoutExtent e = layout_extent(layout, cube_size);
    uint64_t total = 0;
    for (uint32_t m = 0; m < mips; ++m) total += uint64_t(std::max(1u, e.width >> m)) * std::max(1u, e.height >> m) * e.layers;
    return total;
}

void check_layout_mips(EnvLayout layout, uint32_t cube_size, uint32_t mips) {
    if (layout == EnvLayout::cube || mips == 0) return;
    LayoutExtent e = layout_extent(layout, cube_size);
    uint32_t w = std::max(1u, e.width >> (mips - 1)), h = std::max(1u, e.height >> (mips - 1));
    if (std::min(w, h) < 3)
        throw UsageError("option 'env_layout': " + std::string(layout_name(layout)) +
                         " with cube_size=" + std::to_string(cube_size) + " and mips=" + std::to_string(mips) + " ends at a " +
                         std::to_string(w) + "x" + std::to_string(h) +
                         " level, which leaves nothing inside its 1-texel border; use mips <= " + std::to_string(mips - 1));
}

Uv octahedral_encode(const Dir& d) {
    double s = std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]);
    double px = d[0] / s, py = d[1] / s;
    if (d[2] < 0) {
        double fx = (1 - std::fabs(py)) * sign_nz(px), fy = (1 - std::fabs(px)) * sign_nz(py);
        px = fx;
        py = fy;
    }
    return {px * 0.5 + 0.5, py * 0.5 + 0.5};
}

Dir octahedral_decode(const Uv& uv) {
    double px = uv[0] * 2 - 1, py = uv[1] * 2 - 1;
    double z = 1 - std::fabs(px) - std::fabs(py);
    if (z < 0) {
        double fx = (1 - std::fabs(py)) * sign_nz(px), fy = (1 - std::fabs(px)) * sign_nz(py);
        px = fx;
        py = fy;
    }
    return normalized({px, py, z});
}

Uv equirect_encode(const Dir& d) {
    return {0.5 + std::atan2(d[0], -d[2]) / (2 * kPi), std::acos(std::clamp(d[1], -1.0, 1.0)) / kPi};
}

Dir equirect_decode(const Uv& uv) {
    double phi = (uv[0] - 0.5) * 2 * kPi, theta = uv[1] * kPi;
    // u = 0.5 + atan2(x, −z)/2π: x = sin φ sin θ, −z = cos φ sin θ.
    return {std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta)};
}

std::array<int, 2> gutter_source(EnvLayout layout, std::array<int, 2> j, std::array<int, 2> n) {
    if (layout == EnvLayout::octahedral) {
        // Each edge folds onto itself about its midpoint: beyond x = 0 (or n−1) is the same column
        // mirrored in y; then the same for y (a corner lands on the opposite corner).
        if (j[0] < 0)
            j = {0, n[1] - 1 - j[1]};
        else if (j[0] >= n[0])
            j = {n[0] - 1, n[1] - 1 - j[1]};
        if (j[1] < 0)
            j = {n[0] - 1 - j[0], 0};
        else if (j[1] >= n[1])
            j = {n[0] - 1 - j[0], n[1] - 1};
    } else if (layout == EnvLayout::equirect) {
        // Beyond a pole: the pole row, half a turn around; longitude wraps.
        if (j[1] < 0)
            j = {j[0] + n[0] / 2, 0};
        else if (j[1] >= n[1])
            j = {j[0] + n[0] / 2, n[1] - 1};
        j[0] = ((j[0] % n[0]) + n[0]) % n[0];
    }
    return j;
}

Dir layout_texel_direction(EnvLayout layout, uint32_t x, uint32_t y, uint32_t w, uint32_t h) {
    std::array<int, 2> n{int(w) - 2, int(h) - 2};
    std::array<int, 2> j = gutter_source(layout, {int(x) - 1, int(y) - 1}, n);
    Uv uv{(j[0] + 0.5) / n[0], (j[1] + 0.5) / n[1]};
    return layout == EnvLayout::octahedral ? octahedral_decode(uv) : equirect_decode(uv);
}

double layout_texel_solid_angle(EnvLayout layout, uint32_t x, uint32_t y, uint32_t w, uint32_t h, int sub) {
    const double nx = double(w) - 2, ny = double(h) - 2;
    auto decode = [&](double u, double v) {
        return layout == EnvLayout::octahedral ? octahedral_decode({u, v}) : equirect_decode({u, v});
    };
    double total = 0, du = 1.0 / (nx * sub), dv = 1.0 / (ny * sub), e = 1e-7;
    for (int b = 0; b < sub; ++b)
        for (int a = 0; a < sub; ++a) {
            double u = (double(x) - 1 + (a + 0.5) / sub) / nx, v = (double(y) - 1 + (b + 0.5) / sub) / ny;
            // Central differences of the unit direction; |∂d/∂u × ∂d/∂v| is the area element.
            Dir pu = decode(u + e, v), mu = decode(u - e, v), pv = decode(u, v + e), mv = decode(u, v - e);
            Dir gu{(pu[0] - mu[0]) / (2 * e), (pu[1] - mu[1]) / (2 * e), (pu[2] - mu[2]) / (2 * e)};
            Dir gv{(pv[0] - mv[0]) / (2 * e), (pv[1] - mv[1]) / (2 * e), (pv[2] - mv[2]) / (2 * e)};
            Dir c{gu[1] * gv[2] - gu[2] * gv[1], gu[2] * gv[0] - gu[0] * gv[2], gu[0] * gv[1] - gu[1] * gv[0]};
            total += std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) * du * dv;
        }
    return total;
}

} // namespace iblcheck
