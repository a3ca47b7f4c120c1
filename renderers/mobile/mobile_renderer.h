// The system under test: the mobile split-sum IBL pipeline on Vulkan (issue 4).
#pragma once
#include "gpu_session.h"
#include "ibl_precompute.h"
#include "renderers/environments/environment.h"
#include "renderers/render_api.h"

namespace iblcheck {
RenderResult render_mobile(GpuSession& gpu, const Environment& env, const TestSpec& spec);
// The precompute a mobile render of `spec` asks for (throws UsageError on a bad option, as the render would).
PrecomputeSettings mobile_precompute_settings(const TestSpec& spec);
} // namespace iblcheck
