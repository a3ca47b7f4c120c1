// Which FLIP kernel variant runs (flip/kernels.h).
#include <cstdlib>

#include "kernel/errors.h"
#include "metrics/flip/kernels.h"

namespace iblcheck::flip {

bool cpu_has_avx2() {
#if defined(__x86_64__) && defined(__GNUC__)
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

const Kernels& kernels_named(const std::string& name) {
    if (name == "scalar") return scalar_kernels();
    if (name == "sse2") return sse2_kernels();
    if (name == "avx2") {
        if (!cpu_has_avx2()) throw EnvironmentError("FLIP kernels 'avx2': this CPU has no AVX2");
#if defined(__x86_64__)
        return avx2_kernels();
#endif
    }
    throw UsageError("FLIP kernels '" + name + "': expected scalar, sse2 or avx2");
}

const Kernels& default_kernels() {
    static const Kernels& k = []() -> const Kernels& {
        if (const char* env = std::getenv("IBLCHECK_FLIP_KERNELS"); env && *env) return kernels_named(env);
#if defined(__x86_64__)
        if (cpu_has_avx2()) return avx2_kernels();
#endif
        return sse2_kernels();
    }();
    return k;
}

std::vector<const Kernels*> available_kernels() {
    std::vector<const Kernels*> out = {&scalar_kernels(), &sse2_kernels()};
#if defined(__x86_64__)
    if (cpu_has_avx2()) out.push_back(&avx2_kernels());
#endif
    return out;
}

} // namespace iblcheck::flip
