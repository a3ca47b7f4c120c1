// The Monte Carlo integrator's per-sphere constants of the model (material_model.h) and the lobes it
// evaluates (option lobes, for tests), shared by the shading (mc_shade.h) and the windows (mc_window.h).
#pragma once
#include "renderers/material_model.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::reference {

inline constexpr double kMirrorAlpha = 1e-4; // below: the specular lobe is the mirror delta
inline constexpr double kMinNdotV = 1e-5;    // n·v clamp (the last sliver of the silhouette)

enum class McLobes { all, diffuse, specular };

// Per-sphere constants: α, α², metallic, F0 and the Lambert term kd = (1−m)·c/π per channel, dw = Σ (1−m)·c
// (the diffuse weight of the lobe choice), and which lobes are evaluated (cont_spec: a GGX lobe, not a mirror).
struct MatConst {
    double alpha, a2, m, f0[3], kd[3], dw;
    bool want_diff, want_spec, mirror, cont_spec;
};

inline MatConst mat_const(const Material& mat, McLobes lobes) {
    MatConst c{};
    c.alpha = model::alpha_from_roughness(mat.roughness);
    c.a2 = c.alpha * c.alpha;
    c.m = mat.metallic;
    const double col[3] = {mat.base_color.x, mat.base_color.y, mat.base_color.z};
    c.want_diff = lobes != McLobes::specular && c.m < 1;
    c.want_spec = lobes != McLobes::diffuse;
    c.mirror = c.alpha < kMirrorAlpha;
    c.cont_spec = c.want_spec && !c.mirror;
    c.dw = 0;
    for (int i = 0; i < 3; ++i) {
        c.f0[i] = model::f0_from(col[i], c.m);
        c.kd[i] = c.want_diff ? (1 - c.m) * col[i] / model::kPi : 0.0;
        c.dw += (1 - c.m) * col[i];
    }
    return c;
}

} // namespace iblcheck::reference
