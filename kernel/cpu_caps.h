// The CPU features llvmpipe generates shader code for (issue 15, "Portable goldens"). lavapipe
// compiles every shader with LLVM for the host CPU, so what a render computes can depend on the CPU:
// the vector width, FMA contraction, and F16C (which is also what gives lavapipe shaderFloat16).
// This module predicts what Mesa 22.3 sees, without Vulkan: /proc/cpuinfo, then Mesa's
// GALLIUM_OVERRIDE_CPU_CAPS rules (src/util/u_cpu_detect.c, check_cpu_caps_override and
// check_max_vector_bits), then LP_NATIVE_VECTOR_WIDTH (src/gallium/auxiliary/gallivm/lp_bld_init.c).
// tests/test_cpu_caps.cpp checks it against Mesa's own GALLIUM_DUMP_CPU output on this machine.
#pragma once
#include <string>

namespace iblcheck {

struct LlvmpipeCaps {
    bool sse41 = false, avx = false, avx2 = false, f16c = false, fma = false, avx512 = false;
    int vector_width = 128;    // bits llvmpipe vectorises with (256 with AVX, LP_NATIVE_VECTOR_WIDTH overrides)
    std::string override_caps; // GALLIUM_OVERRIDE_CPU_CAPS as read ("" if unset)
    std::string
    cpu_class() const; // short stable name of what changes llvmpipe's code: e.g. "avx2-fma-f16c-256", "sse4.1-128", "nosse"

    // Beyond the agreed fields: the SSE levels below 4.1, which the overrides nosse..ssse3 take
    // away (cpu_class needs them to tell "sse2-128" from "ssse3-128"), and a warning when
    // override_caps is a value Mesa 22.3 does not recognise (it then ignores it, e.g. "avx2").
    bool sse = false, sse2 = false, sse3 = false, ssse3 = false;
    std::string warning;
};

// From /proc/cpuinfo flags, then Mesa 22.3's GALLIUM_OVERRIDE_CPU_CAPS rules (u_cpu_detect.c) and LP_NATIVE_VECTOR_WIDTH.
// llvmpipe_caps() also honours GALLIUM_NOSSE, which Mesa applies before the override.
LlvmpipeCaps llvmpipe_caps();
// cpuinfo_flags: the flags of one processor ("fpu vme ... avx2 ..."; a whole "flags : ..." line or
// all of /proc/cpuinfo also do: the first flags line is used). Null pointers mean "unset".
LlvmpipeCaps llvmpipe_caps_from(const std::string& cpuinfo_flags, const char* override_caps, const char* native_vector_width);

} // namespace iblcheck
