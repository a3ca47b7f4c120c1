// The Monte Carlo integrator's environment distribution (monte_carlo.h, "environment sampling"): a
// piecewise-constant 2D distribution over the equirect pixels ∝ luminance (3x3 max) × solid angle,
// sampled uniformly in solid angle inside a pixel, with guide tables and coarse cells for the windowed
// strategy (mc_window.h); and the Owen-scrambled Sobol numbers every sample of the integrator uses.
// Tests: tests/test_reference_env_sampling.cpp.
#pragma once
#include <cstdint>
#include <vector>

#include "renderers/environments/environment.h"

namespace iblcheck {

namespace reference {

// Piecewise-constant environment distribution (see above), in WORLD directions (rotation applied).
class EnvDistribution {
  public:
    // compensation κ ≥ 0: the sampled luminance is max(0, Y − κ·Ȳ), Ȳ the environment's mean luminance
    // over the sphere (MIS compensation, Karlík et al. 2019; see env_distribution.cpp). 0: plain luminance.
    explicit EnvDistribution(const Environment& env, double compensation = 0.0);
    bool empty() const { return total_ <= 0; }
    // Samples a world direction from (u1, u2) in [0,1)²; returns its solid-angle pdf (0: no sample).
    double sample(double u1, double u2, double dir[3]) const;
    double pdf(const double dir[3]) const;
    // The same in equirect uv (u, v in [0,1), env space, i.e. after undoing the rotation): sample_uv
    // also returns the sample's uv, to_uv maps a world direction to it, pdf_uv is pdf() at a uv.
    double sample_uv(double u1, double u2, double dir[3], double& u, double& v) const;
    void to_uv(const double dir[3], double& u, double& v) const;
    double pdf_uv(double u, double v) const;

    // Coarse cells (at most 128x64, each a block of equirect pixels) for the per-pixel windowed
    // distribution (mc_window.h, EnvWindow): sampling cell c with probability P_c and then a pixel of
    // c from this distribution restricted to c gives the solid-angle pdf  pdf(ω) · P_c / (W_c / total),
    // W_c the cell's mass. The window only rescales whole cells, so pdf() and a per-cell factor give
    // any windowed pdf exactly.
    int cells_x() const { return cw_; }
    int cells_y() const { return ch_; }
    int cell_of_uv(double u, double v) const;
    double cell_mass(int c) const { return cell_mass_[size_t(c)]; }              // W_c / total, sums to 1
    const double* cell_centre(int c) const { return &cell_dir_[size_t(c) * 3]; } // world direction
    double cell_solid_angle(int c) const { return cell_omega_[size_t(c)]; }
    double cell_radius(int c) const { return cell_rad_[size_t(c)]; }         // angular radius (rad)
    double cell_cos_radius(int c) const { return cell_cos_rad_[size_t(c)]; } // cos of its angular radius
    double cell_sin_radius(int c) const { return cell_sin_rad_[size_t(c)]; }
    // Samples a pixel of cell c from (u1, u2) (u2 picks the row, u1 the column); returns pdf(ω), the
    // UNwindowed pdf of the direction (0: empty cell).
    double sample_in_cell(int c, double u1, double u2, double dir[3], double& u, double& v) const;

  private:
    // The constructor's steps: the per-pixel CDFs (∝ 3x3-max luminance × solid angle), then (when the
    // environment has any luminance) the per-pixel pdf, the guide tables and the coarse cells.
    std::vector<double> build_pixel_cdfs(const cv::Mat& equirect, double compensation);
    void build_pixel_pdf(const std::vector<double>& pixel_mass);
    void build_guide_tables();
    void build_cells();
    void set_cell_cone(int c, double u0, double u1, double v0, double v1);
    double place(int i, int j, double du, double dv, double dir[3], double& u, double& v) const;
    void env_to_world(const double e[3], double d[3]) const;
    int w_ = 0, h_ = 0;
    int cw_ = 0, ch_ = 0;                // cells
    std::vector<int> cell_i0_, cell_j0_; // cw_ + 1, ch_ + 1 pixel bounds
    std::vector<double> cell_mass_;      // cw_ * ch_, fraction of total
    std::vector<double> cell_dir_;       // cw_ * ch_ * 3
    std::vector<double> cell_rad_, cell_cos_rad_, cell_sin_rad_, cell_omega_;
    std::vector<double> cell_row_cdf_; // per cell: CDF over its pixel rows of the row masses within the cell
    std::vector<size_t> cell_row_off_; // offset of each cell's CDF (rows + 1 entries)
    double total_ = 0;
    double rot_c_ = 1, rot_s_ = 0;        // env -> world rotation by +rotation_deg about +Y
    std::vector<double> marginal_cdf_;    // h_ + 1
    std::vector<double> conditional_cdf_; // h_ * (w_ + 1)
    std::vector<int> marginal_guide_;     // h_ (cutpoint guide table)
    std::vector<int> conditional_guide_;  // h_ * w_
    std::vector<float> pdf_;              // w_ * h_, solid-angle pdf of each pixel
    std::vector<double> row_dcos_;        // h_: cos θ_top − cos θ_bottom of each row
    std::vector<double> row_cos_top_;     // h_
};

// Last index i in [lo, hi) with cdf[i] <= t (cdf non-decreasing; the bin [cdf[i], cdf[i+1]) holds t),
// stepping back off empty bins.
inline int search_cdf(const double* cdf, int lo, int hi, double t) {
    int a = lo, b = hi - 1;
    while (a < b) {
        int m = (a + b + 1) / 2;
        if (cdf[m] <= t)
            a = m;
        else
            b = m - 1;
    }
    while (a > lo && cdf[a + 1] - cdf[a] <= 0) --a;
    return a;
}

// Sobol dimension 1 (primitive polynomial x + 1; dimension 0 is the index's bits reversed): the XOR of the
// direction numbers v_k, v_0 = 2^31 and v_{k+1} = v_k ^ (v_k >> 1), over the set bits k of the index.
// Looked up a byte at a time: a loop over the bits branched on every bit of an Owen-shuffled (random)
// index; sobol_owen_2d was 16 % of the reference integrator's windowed and dielectric furnace tests
// (perf; 8 % after).
uint32_t sobol_dim1(uint32_t index);
// Owen-scrambled shuffled Sobol pair (Burley 2020) in [0,1)², deterministic in (index, seed).
void sobol_owen_2d(uint32_t index, uint32_t seed, double& x, double& y);
uint32_t hash_u32(uint32_t x);

} // namespace reference

} // namespace iblcheck
