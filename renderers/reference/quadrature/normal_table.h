// L_o(n) tabulated over normals: under the orthographic camera the view v is the same at every point
// of a sphere, so its outgoing radiance is a function of the normal alone. One table serves every
// pixel of the sphere (and every frame of bumpy_sphere, whose bumps only move which normals a pixel
// sees), so the footprint integral costs lookups, not quadratures.
//
// Parametrisation: Lambert's azimuthal equal-area map around v, (X, Y) = √(2/(1 + n·v))·(n·right, n·up),
// over n·v ≥ min_nv (|(X, Y)| ≤ √(2(1 − min_nv)): 0 for a smooth sphere, −0.5 for bump normals, which lean
// at most ~0.23 rad past the silhouette). Unlike image positions, it is smooth up to the silhouette.
// Adaptive: a coarse grid of cells (spacing `coarse`), each the root of a quadtree. A cell evaluates
// its centre and edge midpoints (lobe_quadrature.h shading points) and is split when one of them
// differs from the bilinear prediction of the corners by more than tolerance·(|value| + floor) (weighted
// by n·v: the image area those normals cover under the orthographic camera), or when
// it is `forced`: a lobe narrower than the cell (α < its size) in front of a contrasted part of the
// environment (its reflection cone's radiance range), where a feature could hide between the test
// points. A leaf interpolates biquadratically between its 3x3 known values (corners, edge midpoints,
// centre): the split test measures the bilinear interpolant's error, the leaf's is an order smaller.
// Every node keeps the range of the values below it: the footprint integral's variation bound.
#pragma once
#include <functional>
#include <vector>

#include "renderers/reference/quadrature/env_pyramid.h"
#include "renderers/reference/quadrature/lobe_quadrature.h"
#include "renderers/reference/quadrature/truth_math.h"

namespace iblcheck::truth {

struct TableParams {
    double coarse = 1.0 / 8;  // coarse cell size (equal-area units, ≈ radians at n = v)
    double tolerance = 1e-3;  // relative interpolation error that splits a cell
    double floor = 0;         // absolute radiance added to |value| in the tolerance
    int max_depth = 8;        // cells down to coarse / 2^max_depth
    double kappa = 1;         // forced while the cell is wider than κ·α
    double min_nv = 0;        // the table covers n·v ≥ min_nv (−0.5 for bump normals)
    double weight_offset = 0; // errors weigh by clamp(n·v + offset, 0.02, 1) (the image area; bumps: 0.3)
    double footprint = 0;     // a pixel's size in normal space: smaller cells are tested on their integral
};

class NormalTable {
  public:
    // `progress` receives the fraction of coarse cells done (from the building threads, serialised).
    NormalTable(const EnvPyramid& env, const MaterialLobe& lobe, V3 v, V3 right, V3 up, const TableParams& tp,
                const QuadratureParams& qp, int threads, const std::function<void(double)>& progress = {});
    void lookup(V3 n, double rgb[3]) const;
    // Bound on the range (rgb_size of hi − lo) of lookup() over the normals within `radius` of n.
    double variation(V3 n, double radius) const;
    long nodes() const { return nodes_; }       // shading points evaluated
    long evaluations() const { return evals_; } // BRDF evaluations in them
    // Edge midpoints a cell took from its neighbour instead of shading them again (normal_table.cpp,
    // SharedNodes); deterministic, like nodes().
    long shared_nodes() const { return shared_; }
    long leaves() const;
    // The map and its inverse (exposed for tests).
    void to_map(V3 n, double& X, double& Y) const;
    V3 from_map(double X, double Y) const;

  private:
    struct Cell {
        float v[9][3];      // values on the 3x3 grid (row-major from (x0, y0)); leaves only
        float lo[3], hi[3]; // range of every value in the subtree
        int child = -1;     // first of 4 children (x-major: 0 = (−,−), 1 = (+,−), 2 = (−,+), 3 = (+,+))
    };
    struct Builder;
    const Cell* leaf(double X, double Y, double& fx, double& fy) const;
    void range(size_t tree, int cell, double x0, double y0, double s, double bx0, double by0, double bx1, double by1,
               double lo[3], double hi[3]) const;
    V3 v_, r_, u_;
    double x0_ = 0, coarse_ = 0;
    int n_ = 0;                            // coarse cells per side
    std::vector<std::vector<Cell>> trees_; // per coarse cell (row-major), root at index 0
    long nodes_ = 0, evals_ = 0, shared_ = 0;
};

} // namespace iblcheck::truth
