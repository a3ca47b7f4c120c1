// fp16 (IEEE binary16) bit patterns to float, subnormals, infinities and NaN included: the read-back
// of half-float images (resources.cpp) and the ASTC decoder's output (mobile/astc_storage.cpp).
#pragma once
#include <cstdint>
#include <cstring>

namespace iblcheck {

inline float half_bits_to_float(uint16_t h) {
    uint32_t sign = uint32_t(h >> 15) << 31, exp = (h >> 10) & 0x1f, mant = h & 0x3ff, bits;
    if (exp == 0) {
        if (mant == 0)
            bits = sign;
        else { // subnormal: normalise the mantissa
            int e = -1;
            do {
                ++e;
                mant <<= 1;
            } while (!(mant & 0x400));
            bits = sign | uint32_t(127 - 15 - e) << 23 | (mant & 0x3ff) << 13;
        }
    } else if (exp == 31) {
        bits = sign | 0x7f800000u | mant << 13;
    } else {
        bits = sign | (exp + 112) << 23 | mant << 13;
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

} // namespace iblcheck
