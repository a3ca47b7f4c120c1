// The Monte Carlo reference's test spec, shared by the integrator's two test files.
#pragma once
#include <string>

#include "renderers/render_api.h"

namespace iblcheck::testutil {

// method reference at `spp` lighting samples a pixel; w, h = 0: the scene's own size.
inline TestSpec reference_spec(const std::string& scene, const std::string& env, int spp, int w = 0, int h = 0) {
    TestSpec s;
    s.scene = scene, s.env = env, s.method = "reference", s.width = w, s.height = h;
    s.options.set("spp", std::to_string(spp));
    return s;
}

} // namespace iblcheck::testutil
