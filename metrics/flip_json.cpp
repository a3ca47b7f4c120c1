#include "metrics/flip_json.h"

namespace iblcheck {

nlohmann::json flip_json(const FlipResult& r) {
    nlohmann::json j = {{"mean", r.mean},
                        {"weighted_median", r.weighted_median},
                        {"weighted_q1", r.weighted_q1},
                        {"weighted_q3", r.weighted_q3},
                        {"p99", r.p99},
                        {"min", r.min},
                        {"max", r.max},
                        {"block_max", r.block_max},
                        {"block_x", r.block_x},
                        {"block_y", r.block_y},
                        {"mode", r.mode}};
    if (r.mode == "hdr") {
        j["start_exposure"] = r.start_exposure;
        j["stop_exposure"] = r.stop_exposure;
        j["num_exposures"] = r.num_exposures;
        j["exposure_source"] = r.exposure_source;
    }
    return j;
}

} // namespace iblcheck
