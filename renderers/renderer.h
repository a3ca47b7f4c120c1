// The front door of renderers/: render(TestSpec) for any method, the catalogue of methods and
// options (`iblcheck list`), and option validation (unknown keys and values exit 2).
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "option_table.h"
#include "render_api.h"
#include "renderers/vulkan/context.h"

namespace iblcheck {

class GpuSession;
struct Environment;

struct MethodInfo {
    std::string name;
    std::string description;
};
std::vector<MethodInfo> method_catalog();

// Throws UsageError for an unknown method, or an option key that `method` does not read.
void validate_spec(const TestSpec& spec);

// Which GPU precompute a render of `spec` needs (environment spec + settings; empty for the CPU
// truth). Throws UsageError on a bad option, as render() would.
std::string precompute_share_key(const TestSpec& spec);
// Which radiance chain that precompute is derived from (ibl_precompute.h chain_settings: the
// variants that differ only in storage, the DFG table or the irradiance cube share one; empty for
// the CPU truth): the runner gives tests with the same chain to the same worker, whose session
// computes the chain once and each precompute once.
std::string radiance_chain_share_key(const TestSpec& spec);

class Renderer {
  public:
    explicit Renderer(vk::ContextOptions options = {});
    ~Renderer();
    RenderResult render(const TestSpec& spec);
    // The GPU session (created on first use); throws EnvironmentError without a driver.
    GpuSession& gpu();
    const Environment& environment(const std::string& spec);
    // Driver description for provenance: {"device":…, "driver":…, "mesa":…, "llvm":…}; empty
    // until the GPU was used.
    nlohmann::json driver_json();

  private:
    vk::ContextOptions options_;
    std::unique_ptr<GpuSession> gpu_;
    std::map<std::string, std::unique_ptr<Environment>> environments_;
};

} // namespace iblcheck
