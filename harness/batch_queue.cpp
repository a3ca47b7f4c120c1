#include "batch_queue.h"

namespace iblcheck {

BatchQueue::BatchQueue(const std::vector<ChainBatches>& chains) : workers_on_(chains.size(), 0) {
    for (const ChainBatches& c : chains) chains_.emplace_back(c.begin(), c.end());
}

std::optional<Batch> BatchQueue::next(int w) {
    std::lock_guard lock(mutex_);
    size_t chain = chains_.size();
    if (auto on = chain_of_.find(w); on != chain_of_.end()) {
        if (!chains_[on->second].empty())
            chain = on->second;
        else {
            --workers_on_[on->second];
            chain_of_.erase(on);
        }
    }
    if (chain == chains_.size()) {
        for (size_t c = 0; c < chains_.size() && chain == chains_.size(); ++c)
            if (!chains_[c].empty() && workers_on_[c] == 0) chain = c;
        if (chain == chains_.size()) // every chain left has a worker: join the one with the most tests left
            for (size_t c = 0; c < chains_.size(); ++c)
                if (!chains_[c].empty() && (chain == chains_.size() || tests_in(chains_[c]) > tests_in(chains_[chain])))
                    chain = c;
        if (chain == chains_.size()) return std::nullopt;
        ++workers_on_[chain];
        chain_of_[w] = chain;
    }
    Batch b = std::move(chains_[chain].front());
    chains_[chain].pop_front();
    return b;
}

void BatchQueue::close() {
    std::lock_guard lock(mutex_);
    for (auto& c : chains_) c.clear();
}

} // namespace iblcheck
