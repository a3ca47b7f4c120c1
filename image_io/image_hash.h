// A content hash of an image for cache keys (the metrics store's entries, the run's drawn pictures):
// its size, type and pixels, row by row (a view into a larger image hashes as its own pixels).
#pragma once
#include <string>

#include <opencv2/core.hpp>

#include "kernel/hash.h"

namespace iblcheck {

inline void hash_image(Fnv1a64& h, const cv::Mat& m) {
    h.update(std::to_string(m.cols) + "x" + std::to_string(m.rows) + ":" + std::to_string(m.type()) + ";");
    const size_t row_bytes = size_t(m.cols) * m.elemSize();
    for (int y = 0; y < m.rows; ++y) h.update(m.ptr(y), row_bytes);
}

inline std::string image_hash(const cv::Mat& m) {
    Fnv1a64 h;
    hash_image(h, m);
    return h.hex();
}

} // namespace iblcheck
