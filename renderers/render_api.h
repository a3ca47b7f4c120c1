// One interface, three methods (docs/DESIGN.md): render(TestSpec) -> RenderResult.
// A renderer knows nothing of metrics; the harness knows nothing of Vulkan.
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "kernel/options.h"

namespace iblcheck {

struct TestSpec {
    std::string scene = "sphere";
    std::string method = "mobile"; // mobile | sampled | reference
    std::string env = "studio";
    std::string env_name;      // a file environment's stable name (test names, golden keys); empty: its file name
    int width = 0, height = 0; // 0: the scene's default size
    OptionMap options;         // material + method variants, one spelling everywhere
    int frame = 0;             // temporal scenes: frame index
    // mobile: a team's IBL shading file (docs/SHADER_CONTRACT.md) the shading pass calls instead of
    // the built-in split sum; empty: the built-in. An absolute path (the suite or CLI resolves it).
    std::string shader;
};

struct PassTiming {
    std::string name; // "equirect_to_cube", "prefilter_ggx", "shade_spheres", "reference_cpu", ...
    double ms = 0;
    bool gpu = false;        // true: timestamp queries; false: steady clock on the CPU
    bool precompute = false; // environment-dependent work done once (prefilter, SH, LUT)
};

// Which sphere each pixel shows (renderers/scenes/coverage.h): the harness's per-sphere errors, the
// sphere a worst block lies on, and the report's id map come from it.
struct SphereCoverage {
    struct Sphere {
        std::string label; // "metal r=0.3"
        float roughness = 0, metallic = 0;
    };
    cv::Mat ids;                 // CV_32S, the image's size: the sphere at the pixel's centre, -1 background
    std::vector<Sphere> spheres; // the scene's spheres, in index order
};

struct RenderResult {
    cv::Mat image; // CV_32FC3, linear HDR
    std::vector<PassTiming> timings;
    nlohmann::json provenance;            // method, driver, shader hash, samples, seeds, ...
    double texture_fetches_per_pixel = 0; // driver-independent cost estimate
    // Dynamic SPIR-V instructions the frame's shading dispatch executed per image pixel, every ssaa
    // ray included (renderers/vulkan/spirv_cost.h): deterministic, unlike the timings. 0 for the
    // CPU reference and on a device that cannot count.
    double shader_instructions_per_pixel = 0;
    // The environment texture the shading pass samples (mobile: the prefiltered chain) as a device
    // would store it: texels and bytes in its storage format. 0 where a method has none.
    uint64_t texel_count = 0;
    uint64_t texture_bytes = 0;
    SphereCoverage coverage; // filled by Renderer::render() for every method
    // "<shader>: alpha (coverage) channel: N non-finite value(s) (NaN/Inf), first at x=X, y=Y" when
    // the shading pass wrote NaN/Inf coverage (empty otherwise): the shader's fault, a regression.
    // It is reported, not thrown, so the image is still kept for inspection (render --out, run's
    // full-precision render of a failure) before the verdict, as for NaN/Inf pixels.
    std::string non_finite_coverage;
};

} // namespace iblcheck
