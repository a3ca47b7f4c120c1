// The quadrature truth: the image of a scene of spheres under distant light with no occlusion, each
// pixel the average over its footprint of the exact shading, computed deterministically at two
// refinement levels whose difference is the stated error bound (CONVERGENCE.md, "The quadrature truth").
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "renderers/reference/quadrature/env_pyramid.h"
#include "renderers/reference/quadrature/truth_math.h"
#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::truth {

// One refinement level. finer() tightens every control (the bound is the difference between a level
// and its finer one, so the finer one must be finer in every error source): tolerances / 2, guard / √2.
struct TruthAccuracy {
    double pixel_tolerance = 1e-3; // footprint.h, relative per pixel (table and mirror lookups are cheap)
    double env_tolerance = 2.5e-4; // lobe_quadrature.h, relative per shading point (table node)
    double table_tolerance = 2e-2; // normal_table.h, the bilinear error that splits a cell (the leaves
                                   // interpolate biquadratically: their error is an order smaller)
    double floor = 1e-3;           // of every tolerance, × the environment's mean radiance
    double kappa = 2;              // lobe guards (quadrature and table), × the lobe's width (2 instead of 1:
                                   // 21 % less time, the same error: CONVERGENCE.md)
    int bound_depth = 6;           // footprint.h: the variation bound splits squares down to 2^-depth px
    // The temporal sequences' accuracy: a bumped sphere's pixels average a wide cone of normals; the
    // normal table, shared by every frame, is tighter, the footprint looser (CONVERGENCE.md, "The
    // temporal truth").
    static TruthAccuracy temporal();
    TruthAccuracy finer() const;
    nlohmann::json json() const;
};

// Fraction of the work done, in [0, 1] (called from the rendering threads, serialised).
using Progress = std::function<void(double)>;

struct TruthImage {
    cv::Mat image;             // CV_32FC3
    cv::Mat coverage;          // CV_32FC1, exact |pixel ∩ silhouettes|
    cv::Mat sphere;            // CV_32SC1, the sphere covering most of the pixel (−1: background)
    long evaluations = 0;      // BRDF evaluations (all in the normal tables' nodes)
    long table_nodes = 0;      // shading points
    long footprint_points = 0; // table lookups and mirror lookups
    double seconds = 0;
};

struct SphereBound {
    std::string label;
    long pixels = 0;
    double relative_rmse = 0;  // reference.h's definition, over the sphere's covered pixels
    double worst = 0;          // largest per-pixel term |a − b|/√(m² + 0.01) (max over channels)
    double worst_relative = 0; // largest |a − b|/m over pixels with m > 0.01 (max over channels)
    int worst_x = -1, worst_y = -1;
};
struct TruthBound {
    double relative_rmse = 0; // over every covered pixel
    double worst = 0, worst_relative = 0;
    int worst_x = -1, worst_y = -1;
    long covered_pixels = 0;
    std::vector<SphereBound> spheres;
    nlohmann::json json() const;
};
TruthBound compare_levels(const TruthImage& coarse, const TruthImage& fine, const Scene& scene);

struct TruthRender {
    RenderResult result; // image = the finer level, provenance with the bound
    TruthImage coarse, fine;
    TruthBound bound;
};
// Smooth spheres with a glossy lobe narrower than this (roughness below ~0.045) are refused (see
// render_truth): the Monte Carlo integrator renders them.
inline constexpr double kNearMirrorAlpha = 2e-3;

// spec.options: the scene's options, env_rotation, lobes, threads, truth_tolerance (the coarse level's
// pixel tolerance, default 1e-3; its env tolerance is a quarter of it), split_sum (off: the truth;
// exact | env_brdf_approx: split_sum.h's rungs, rendered at the coarse level only — its bound against
// the finer level is the truth's own, measured on the truth (split_sum=off) render of the scene). Throws UsageError for a
// perspective camera, overlapping silhouettes (the quadrature integrates each disc's footprint on its
// own) or a near-mirror lobe on a smooth sphere (kNearMirrorAlpha).
TruthRender render_truth(const TestSpec& spec, const Environment& env, const Progress& progress = {});

// One level (tests, measurements). env_key identifies the environment and its rotation (the normal
// tables of bumped spheres are cached under it across renders).
TruthImage render_truth_level(const Scene& scene, int W, int H, const EnvPyramid& env, const std::string& env_key, Lobes lobes,
                              const TruthAccuracy& acc, int threads, const Progress& progress = {},
                              SplitSum split_sum = SplitSum::off);

} // namespace iblcheck::truth
