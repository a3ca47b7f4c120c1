// Where a render's spheres lie, and the error per sphere: the per-sphere breakdown of an error map
// by the render's sphere coverage (which the renderer reports: renderers/scenes/coverage.h). The
// comparison itself is metrics/image_compare.h's.
#pragma once
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "renderers/render_api.h"

namespace iblcheck {

// Mean FLIP per sphere of a multi-sphere scene (null for single-sphere scenes), labelled with the
// scene's sphere names. `coverage`: the render's (RenderResult::coverage), the error map's size.
nlohmann::json per_sphere_errors(const SphereCoverage& coverage, const cv::Mat& errmap);

// Where each sphere lies in a render, for the report's "what is under the pointer": `ids` (CV_8U,
// the render's size) holds 0 for the background and i + 1 for sphere i (at most 254 spheres, else
// empty); `spheres` lists {label, roughness, metallic} in that order.
struct SphereLayout {
    cv::Mat ids;
    nlohmann::json spheres = nlohmann::json::array();
};
SphereLayout sphere_layout(const SphereCoverage& coverage);

// The sphere under pixel (x, y) of a render ("metal r=0.3"), or "" for the background.
std::string sphere_at(const SphereCoverage& coverage, int x, int y);

} // namespace iblcheck
