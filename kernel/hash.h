// FNV-1a 64-bit: a small, stable content hash for cache keys and provenance (not cryptographic).
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace iblcheck {

class Fnv1a64 {
  public:
    void update(const void* data, size_t n) {
        auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ull;
    }
    void update(std::string_view s) { update(s.data(), s.size()); }
    uint64_t value() const { return h_; }
    std::string hex() const {
        char buf[17];
        std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
        return buf;
    }

  private:
    uint64_t h_ = 0xcbf29ce484222325ull;
};

} // namespace iblcheck
