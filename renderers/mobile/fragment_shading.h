// shading=fragment (issue 18): the mobile split sum as a phone runs it, in a graphics pipeline.
// Each sphere is a screen-space impostor (shade_spheres.vert/.frag): a quad whose fragment shader
// intersects the analytic sphere, writes the hit's depth, sets per-sample coverage at the
// silhouette and discards what covers no sample. MSAA 4x (the mobile default), one shading per
// pixel, resolved by averaging the samples; specular AA takes dFdx/dFdy from the hardware quads.
// The shading itself is the compute path's (split_sum.glsl).
#pragma once
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "gpu_session.h"
#include "push_constants.h"
#include "renderers/render_api.h"

namespace iblcheck {

struct FragmentShadingPass {
    vk::Defines defines;               // the option table's, as the compute pass gets them
    vk::CompileOptions options;        // fp16 emulation
    std::vector<vk::Binding> bindings; // 0..4 as the compute pass binds them (no output buffer)
    ShadePush push;                    // width, height: the image; ssaa: supersampling factor
    uint32_t sphere_count = 0;
    // shading_inputs_hash() of what the bindings hold: the count is stored under it (cost_store.h);
    // empty: counted every time.
    std::string inputs_hash;
};

struct FragmentShadingResult {
    cv::Mat image;       // CV_32FC3, the image's size
    double coverage = 0; // mean resolved alpha: the fraction of samples covered
    // Fragments that covered a sample and ran the shading, per image pixel (ssaa² per pixel
    // inside a sphere, 1 at its silhouette): what the texture fetches scale with.
    double shaded_fragments_per_pixel = 0;
    std::vector<PassTiming> timings; // "shade_spheres_fragment": the render pass, resolve included
    // SPIR-V instructions the draw executed (vertex + fragment invocations, helpers excepted:
    // they cannot write the counter) per image pixel; nullopt where the device cannot count.
    std::optional<double> instructions_per_pixel;
    std::string non_finite_coverage; // coverage_problem() of the samples (RenderResult's)
};

// EnvironmentError when the device cannot draw it (graphics queue, 4x MSAA, standard sample
// locations); Error when the instruction-counting twin draws another image than the timed draw.
FragmentShadingResult shade_fragment(GpuSession& gpu, const FragmentShadingPass& pass);

// Averages each ssaa×ssaa block of a width·ssaa × height·ssaa RGBA float image: rgb into `rgb`
// (CV_32FC3, width × height), and returns the mean alpha over the whole image.
double box_downsample_rgba(const float* rgba, int width, int height, int ssaa, cv::Mat& rgb);

} // namespace iblcheck
