// The error budget of a mobile IBL configuration (`iblcheck explain`, issue 26): a ladder of renders
// from the truth to the configuration, each rung replacing one exact stage by its approximation, so
// that the change in error between consecutive rungs is that approximation's share (the shares
// telescope: they sum to the last rung's error, the total).
//
//   truth                      the quadrature truth (goldens/reference when it exists)
//   split_sum                  reference split_sum=exact: the n = v = R lobe assumption alone
//   env_brdf_approx            reference split_sum=env_brdf_approx: EnvBRDFApprox for the exact DFG
//   mip_chain                  mobile, converged: prefilter_samples 4096, irradiance cube, rgba32f,
//                              highp, ssaa 8, env_brdf approx; the configuration's cube_size, mips,
//                              mip_mapping, env_layout (and every option no step below names): the
//                              prefiltered mip chain (base size, levels, roughness-to-mip curve,
//                              trilinear), with the irradiance cube's and 8x8 pixel sampling's residue
//   then, one at a time in pipeline order, each option where the configuration differs from the
//   converged value: ssaa, prefilter_samples, diffuse, env_brdf, storage, precision, specular_aa,
//   dominant_dir, normalization.
//
// Interaction: each GPU step is also rendered alone on the converged state (its isolated effect);
// total = Σ isolated (the three first rungs' shares are their isolated effects: they are the base)
// + the interaction term. Order dependence is measured by walking another order (--order).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "kernel/options.h"
#include "renderers/render_api.h"

namespace iblcheck {

struct BudgetRung {
    std::string key;   // "split_sum", "env_brdf_approx", "mip_chain", or the option a GPU step sets
    std::string label; // for the table: "prefilter_samples 4096 -> 256"
    TestSpec spec;
};
struct BudgetPlan {
    TestSpec truth;
    std::vector<BudgetRung> ladder;   // in order; the last is the configuration itself
    std::vector<BudgetRung> isolated; // GPU steps alone on the converged state (ladder's "mip_chain")
};

// The converged GPU state's values of the options the steps walk (the order of the steps).
const std::vector<std::pair<std::string, std::string>>& converged_gpu_values();

// The ladder for `config` (the --set options of a mobile configuration). `order`: steps to walk
// first, in that order (the rest keep the pipeline order). Throws UsageError naming an option the
// truth does not model (ao != 1), one that is not a mobile or scene option (truth_tolerance and
// threads pass to the CPU rungs), or an unknown step in `order`.
BudgetPlan plan_budget(const std::string& scene, const std::string& env, const OptionMap& config,
                       const std::vector<std::string>& order = {});

// A render's error against the truth, per sphere (sphere at the pixel centre, coverage.ids) and over
// every covered pixel: signed relative bias Σ(t − r)/Σr, relative RMSE √(mean (t − r)²)/mean r (the
// three channels pooled), mean HDR-FLIP (the runner's: metrics/image_compare.h).
struct ErrorFigures {
    double bias = 0, rmse = 0, flip = 0;
};
struct RungErrors {
    ErrorFigures image;
    std::vector<ErrorFigures> spheres; // per coverage.spheres index (zero for a sphere with no pixel)
};
RungErrors measure_errors(const cv::Mat& truth, const cv::Mat& test, const SphereCoverage& coverage, int flip_threads);

// The budget as JSON: rungs with their errors, shares (consecutive differences), isolated effects,
// the interaction term, and the sums that check them. `steps` (optional, one per rung): each rung's
// image against the previous rung's (the first against the truth): how much the step changes the
// image, which a share (a difference of errors) can understate when errors cancel.
nlohmann::json budget_json(const BudgetPlan& plan, const std::vector<RungErrors>& ladder, const std::vector<RungErrors>& isolated,
                           const SphereCoverage& coverage, const std::vector<RungErrors>& steps = {});

// The terminal table of budget_json's result.
std::string budget_table(const nlohmann::json& budget);

} // namespace iblcheck
