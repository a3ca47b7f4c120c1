// Thread count of the FLIP engine. The engine hands whole strips (and, for narrow images, row
// bands) to threads; every output pixel is computed by exactly one thread with the same
// arithmetic, so results do not depend on the thread count (metrics/flip.cpp).
#pragma once
#include <algorithm>
#include <thread>

namespace iblcheck::flip {

inline int resolve_threads(int requested) {
    if (requested > 0) return requested;
    return std::max(1, int(std::thread::hardware_concurrency()));
}

} // namespace iblcheck::flip
