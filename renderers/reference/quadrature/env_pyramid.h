// The environment as a pyramid of cells with exact integrals, for deterministic quadrature.
//
// The integrand is environment.h's radiance: the equirect with its bilinear filter (texel centres at
// (i + 0.5)/W, u wraps, v clamps) — the same function the Monte Carlo integrator samples. Level 0 holds
// one cell per texel with the EXACT integral of that bilinear function over the texel's solid angle
// (in u the interpolant integrates to (L[i−1] + 6 L[i] + L[i+1])/8 of the texel's width; in θ the
// weights are closed-form integrals of the linear interpolant against sin θ; clamped rows repeat the
// edge row as the filter does). Level k > 0 cells are 2^k × 2^k blocks of texels (ragged at the
// right/bottom for sizes that are not powers of two), their integrals exact sums. Each cell also keeps
// its luminance-weighted centroid direction and second moment about it (the quadrature rule's points
// match them: lobe_quadrature.h), its geometric
// centre and angular radius (culling and the lobe guard), and the range of radiance its bilinear
// values can take (min/max per channel over the texels it reads).
// Sub-texel cells (level −s: a texel split into 2^s × 2^s in φ and in cos θ steps of θ) are evaluated
// on the fly: bilinear radiance at the cell's solid-angle centre times its exact solid angle.
// All directions are WORLD directions: env.rotation_deg is applied.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "renderers/environments/environment.h"
#include "renderers/reference/quadrature/truth_math.h"

namespace iblcheck::truth {

struct EnvCell {
    float L[3];     // ∫ L dω over the cell (RGB)
    float c[3];     // luminance-weighted centroid direction (unit; the geometric centre if black)
    float cov[6];   // luminance-weighted second moment of the directions about c (xx xy xz yy yz zz)
    float mlen;     // |mean direction vector| (< 1): the mean vector is mlen·c
    float sp[4][3]; // the quadrature rule's points (lobe_quadrature.h): c ± √2·l_k, l_k the columns of
    int np;         // the Cholesky factor of cov on c's tangent plane; 1 point (c) when cov vanishes
    float m[3][3];  // per channel q, the mean direction vector ∫L_q ω dω / ∫L_q dω
    // Per channel q, the rule's weights on sp[0..3] are L_q·(1/4 + a, 1/4 − a, 1/4 + b, 1/4 − b) with
    // (a, b) = wa[q]: the offsets that move the rule's first moment from the luminance's mean to channel q's
    // own (|a|, |b| ≤ 1/4). A cell whose colour changes across it (sky beside foliage) is then integrated
    // to second order in every channel, not only in luminance, with the same four BRDF evaluations.
    float wa[3][2];
    float g[3];         // geometric centre direction (unit)
    float cos_radius;   // cos of the largest angle from g to the cell's edge
    float radius;       // that angle (acos of cos_radius, kept: the quadrature's guard compares angles)
    float lo[3], hi[3]; // range of the bilinear radiance inside the cell (per channel)
};

class EnvPyramid {
  public:
    explicit EnvPyramid(const Environment& env);
    int levels() const { return int(w_.size()); } // level 0 .. levels() − 1
    int width(int level) const { return w_[size_t(level)]; }
    int height(int level) const { return h_[size_t(level)]; }
    const EnvCell& cell(int level, int i, int j) const { return cells_[size_t(level)][size_t(j) * w_[size_t(level)] + i]; }
    // Exact solid angle of texel row j (each texel of the row): (2π/W)(cos θ_j − cos θ_{j+1}).
    double texel_solid_angle(int j) const { return texel_omega_[size_t(j)]; }
    // The level whose cells are about 45 degrees (8 x 4 of them for a 2:1 panorama), where the
    // quadrature starts.
    int top_level() const { return top_; }
    // Bilinear radiance (environment.h's filter) in a world direction.
    void radiance(V3 dir, double rgb[3]) const;
    // A sub-texel cell: texel (i, j) of level 0 split into n × n (n = 2^s), sub-cell (a, b): its
    // solid-angle centre direction, exact solid angle, and the bilinear radiance there.
    void subcell(int i, int j, int n, int a, int b, V3& dir, double& omega, double rgb[3]) const;
    // World direction inside texel (i, j) at fractions (fu, ft) ∈ [0,1]² across φ and θ, and sin θ
    // there: the edges' sines/cosines are tabulated and the small offsets added by angle sums (no libm
    // trigonometry in the quadrature's inner loop).
    V3 dir_in_texel(int i, double fu, int j, double ft, double* sin_theta = nullptr) const;
    // The 2x2 Gauss–Legendre rule of a sub-texel cell in (u, θ) (the bilinear radiance is smooth inside
    // a quarter texel): its nodes' directions and radiance × weight (∫ ≈ Σ f(dir_k)·wL_k).
    void subcell_gauss(int i, int j, int n, int a, int b, V3 dir[4], double wL[4][3]) const;
    // Angular radius bound of a sub-texel cell (as subcell()'s arguments), and its cosine (tabulated per
    // row and sub-level: the quadrature asks for it at every sub-texel cell).
    double subcell_radius(int j, int n, int b) const;
    double subcell_cos_radius(int j, int n) const { return sub_cos_[size_t(__builtin_ctz(unsigned(n)))][size_t(j)]; }
    // A cell as a rectangle in the tangent plane at its solid-angle centre g: ex along φ, ey along θ
    // (unit, world), half-extents hx = sin θ_g·Δφ/2 and hy = Δθ/2 (level ≥ 0: (level, i, j); sub-texel
    // level −s: texel (i, j), sub-cell (a, b)). Used to clip a cell at the horizon.
    struct Rect {
        V3 g, ex, ey;
        double hx, hy;
    };
    Rect rect(int level, int i, int j, int a = 0, int b = 0) const;
    // Range of radiance (per channel) over all directions within `radius` of `dir` (conservative:
    // the cells of one level that overlap the cone's θ/φ bounding box).
    void radiance_range(V3 dir, double radius, double lo[3], double hi[3]) const;
    // The cells of `level` overlapping the θ/φ bounding box of the cone (dir, radius), each once.
    void cone_cells(V3 dir, double radius, int level, std::vector<std::pair<int, int>>& out) const;
    // The angular size of a level's cells in θ.
    double cell_angle(int level) const { return double(1 << level) * kPi / H_; }
    // Mean of rgb_size(radiance) over the sphere of directions.
    double mean_radiance() const { return mean_; }
    V3 to_env(V3 world) const { return {rc_ * world.x - rs_ * world.z, world.y, rs_ * world.x + rc_ * world.z}; }
    V3 to_world(V3 e) const { return {rc_ * e.x + rs_ * e.z, e.y, -rs_ * e.x + rc_ * e.z}; }

  private:
    void build_level0(const cv::Mat& m);
    void build_level(int k);
    void cone_box(V3 dir, double radius, int& i0, int& i1, int& j0, int& j1) const;
    static void set_uniform_cov(EnvCell& c, const Rect& r);
    void set_texel_moments(EnvCell& c, int i, int j) const;
    int W_ = 0, H_ = 0, top_ = 0;
    double rc_ = 1, rs_ = 0, mean_ = 0;
    std::vector<float> data_; // the equirect, RGB rows
    std::vector<int> w_, h_;
    std::vector<std::vector<EnvCell>> cells_;
    std::vector<double> texel_omega_, row_z_;   // row_z_: cos θ at row edges (H + 1)
    std::vector<double> row_s_, col_s_, col_c_; // sin θ at row edges; sin φ, cos φ at column edges
    std::vector<std::vector<double>> sub_cos_;  // [log2 n][row]: cos of subcell_radius
    // sin and cos of φ at fraction fu across texel column i, and of θ at fraction ft down texel row j.
    void phi_sc(int i, double fu, double& s, double& c) const;
    void theta_sc(int j, double ft, double& s, double& c) const;
    bool taylor_ = true; // texels small enough for the angle-sum series
};

} // namespace iblcheck::truth
