// Magma rendering of a FLIP error map (metrics/flip.h).
#include "kernel/errors.h"
#include "metrics/flip.h"
#include "metrics/flip/magma_table.h"

namespace iblcheck {

cv::Mat magma_heatmap(const cv::Mat& errmap) {
    if (errmap.type() != CV_32F) throw InputError("magma_heatmap: error map must be CV_32F");
    cv::Mat out(errmap.size(), CV_32FC3);
    for (int y = 0; y < errmap.rows; ++y) {
        const float* e = errmap.ptr<float>(y);
        float* o = out.ptr<float>(y);
        for (int x = 0; x < errmap.cols; ++x) {
            // The tool's lookup: round to the nearest of 256 entries, wrapping like its modulo.
            int idx = int(e[x] * 255.0f + 0.5f) % 256;
            if (idx < 0) idx = 0;
            o[3 * x + 0] = flip::kMagma[idx][0];
            o[3 * x + 1] = flip::kMagma[idx][1];
            o[3 * x + 2] = flip::kMagma[idx][2];
        }
    }
    return out;
}

} // namespace iblcheck
