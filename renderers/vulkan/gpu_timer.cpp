// Timestamp queries around passes (GpuTimer, context.h).
#include "context.h"
#include "kernel/errors.h"
#include "vk_struct.h"

namespace iblcheck::vk {

// Queries per pass: begin, the marker that resolves it (see context.h), end.
constexpr uint32_t kQueriesPerPass = 3;

GpuTimer::GpuTimer(Context& ctx, uint32_t max_passes) : ctx_(ctx), max_(max_passes) {
    auto qi = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = kQueriesPerPass * max_passes;
    check(vkCreateQueryPool(ctx.device(), &qi, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
    if (pool_) vkDestroyQueryPool(ctx_.device(), pool_, nullptr);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
    vkCmdResetQueryPool(cmd, pool_, 0, kQueriesPerPass * max_);
    names_.clear();
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
    if (names_.size() >= max_) throw Error("GpuTimer: more passes than reserved");
    const uint32_t q = uint32_t(kQueriesPerPass * names_.size());
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, q);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, q + 1); // resolves q on lavapipe
    names_.push_back(name);
}

void GpuTimer::end(VkCommandBuffer cmd) {
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, uint32_t(kQueriesPerPass * names_.size() - 1));
}

std::vector<std::pair<std::string, double>> GpuTimer::results() const {
    std::vector<std::pair<std::string, double>> out;
    if (names_.empty()) return out;
    std::vector<uint64_t> ts(kQueriesPerPass * names_.size());
    check(vkGetQueryPoolResults(ctx_.device(), pool_, 0, uint32_t(ts.size()), ts.size() * 8, ts.data(), 8,
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    for (size_t i = 0; i < names_.size(); ++i)
        out.emplace_back(names_[i],
                         double(ts[kQueriesPerPass * i + 2] - ts[kQueriesPerPass * i]) * ctx_.info().timestamp_period_ns * 1e-6);
    return out;
}

} // namespace iblcheck::vk
