// The importance-sampled peer (Substance Painter's approach, third seed): the estimator is
// shaders/shade_sampled.comp; it reuses the mobile pipeline's source pyramid, SH9 and scene upload.
#pragma once
#include "renderers/environments/environment.h"
#include "renderers/mobile/gpu_session.h"
#include "renderers/mobile/ibl_precompute.h"
#include "renderers/render_api.h"

namespace iblcheck {
RenderResult render_sampled(GpuSession& gpu, const Environment& env, const TestSpec& spec);
// The source pyramid and SH9 a sampled render of `spec` asks for (no prefiltered chain).
PrecomputeSettings sampled_precompute_settings(const TestSpec& spec);
} // namespace iblcheck
