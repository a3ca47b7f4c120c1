// One lighting sample of the Monte Carlo integrator (monte_carlo.h, "Lighting"): at a hit with normal n
// seen from v, one sample of each of two strategies over the whole BRDF (diffuse + specular evaluated
// together), combined by MIS: (a) BRDF sampling (GGX VNDF with probability p_s, else the cosine
// hemisphere), (b) environment sampling (the windowed distribution, mc_window.h). A mirror (α < 1e-4)
// adds its delta F(n·v)·L(reflect(v)) exactly. The sampling functions are mc_sampling.h's.
#pragma once
#include <cstdint>

#include <opencv2/core.hpp>

#include "kernel/vec3.h"
#include "renderers/reference/monte_carlo/env_distribution.h"
#include "renderers/reference/monte_carlo/mc_material.h"
#include "renderers/reference/monte_carlo/mc_window.h"

namespace iblcheck::reference {

// The equirect with environment.h's bilinear filter (sample_bilinear: texel centres at (i + 0.5)/W,
// u wraps, v clamps), addressed by uv so that the direction -> uv trigonometry is done once per
// direction and shared with the pdf lookup.
struct EnvImage {
    const float* data = nullptr;
    int W = 0, H = 0;
    size_t stride = 0; // floats per row
    explicit EnvImage(const cv::Mat& m) : data(m.ptr<float>(0)), W(m.cols), H(m.rows), stride(m.step1()) {}
    void lookup(double u, double v, double rgb[3]) const { bilinear_equirect(data, W, H, stride, u, v, rgb); }
};

// What every sample of a render shares: the environment, its distribution, the lobes, the MIS heuristic.
struct Shader {
    const EnvImage& img;
    const EnvDistribution& dist;
    McLobes lobes;
    bool power = true;  // MIS heuristic: power (β = 2) or balance
    bool window = true; // env_sampling = window (EnvWindow) or global
};

// Per-pixel scramble seeds of the lighting dimensions.
struct LightSeeds {
    uint32_t brdf, select, env;
};

// Shades lighting sample k (Sobol index of the pixel's sequences) at a hit: world normal n, direction to
// the viewer v; adds the estimate into out[3] and counts the environment lookups in `fetches`.
void shade(const Shader& S, const MatConst& M, const EnvWindow& win, Vec3d n, Vec3d v, const LightSeeds& seeds, uint32_t k,
           double out[3], long& fetches);

// f(l)·(n·l) per channel for a local direction l (n·l > 0), and the BRDF strategy's pdf of l (the mixture
// p_s·pdf_vndf + (1−p_s)·n·l/π), sharing the half-vector: material_model.h's equations exactly.
struct BrdfEval {
    const MatConst& M;
    Vec3d vl;       // local view direction, vl.z = n·v (clamped)
    double p_s = 0; // probability of the specular (VNDF) strategy
    BrdfEval(const MatConst& m, Vec3d view_local, double p_specular);
    double operator()(Vec3d l, double fc[3]) const;

  private:
    double nv, vndf_norm, gv_term;
};

// p_s = spec/(spec + diff), spec = Σ_c Schlick(F0_c, n·v), diff = Σ_c (1−m)·c_c, clamped to [0.1, 0.9]
// (1 or 0 when only one lobe is evaluated).
double specular_probability(const MatConst& M, double nv);

} // namespace iblcheck::reference
