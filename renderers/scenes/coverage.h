// Which sphere each pixel of a render shows (render_api.h, SphereCoverage): the sphere the camera
// ray through the pixel's centre hits first, by scene.h's camera_ray() and intersect(), the
// geometry every method renders (scene.glsl mirrors it on the GPU). Renderer::render() fills every
// render's coverage with it, so the harness's per-sphere errors and the report's "what is under the
// pointer" read the render instead of tracing the camera again.
#pragma once
#include "renderers/render_api.h"
#include "renderers/scenes/scene.h"

namespace iblcheck {

// The coverage of a width x height render of `scene`.
SphereCoverage sphere_coverage(const Scene& scene, int width, int height);

} // namespace iblcheck
