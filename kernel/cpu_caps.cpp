#include "cpu_caps.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace iblcheck {

namespace {

// The flags of the first "flags" line when `text` has one (all of /proc/cpuinfo, or one line),
// else every whitespace-separated word of `text`.
std::set<std::string> flag_set(const std::string& text) {
    std::string list = text;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        size_t colon = line.find(':');
        if (line.rfind("flags", 0) == 0 && colon != std::string::npos) {
            list = line.substr(colon + 1);
            break;
        }
    }
    std::set<std::string> flags;
    std::istringstream words(list);
    for (std::string w; words >> w;) flags.insert(w);
    return flags;
}

// Mesa's debug_get_bool_option: unset, "", and the spellings of "no" are false, anything else true
// (checked on Mesa 22.3: GALLIUM_NOSSE=0|no|false|"" keep SSE, 1|yes clear it).
bool mesa_bool(const char* v) {
    if (!v) return false;
    for (const char* no : {"", "0", "n", "N", "no", "NO", "f", "F", "false", "FALSE"})
        if (std::strcmp(v, no) == 0) return false;
    return true;
}

LlvmpipeCaps caps_from(const std::string& cpuinfo_flags, const char* override_caps, const char* native_vector_width, bool nosse) {
    std::set<std::string> f = flag_set(cpuinfo_flags);
    auto has = [&](const char* name) { return f.count(name) != 0; };
    LlvmpipeCaps c;
    // u_cpu_detect.c reads CPUID; the kernel's names for the same bits ("pni" is SSE3). The kernel
    // already hides AVX and beyond when the OS does not save their registers (Mesa's xgetbv check).
    c.sse = has("sse");
    c.sse2 = has("sse2");
    c.sse3 = has("pni");
    c.ssse3 = has("ssse3");
    c.sse41 = has("sse4_1");
    c.avx = has("avx");
    c.f16c = has("f16c") && c.avx;
    c.fma = has("fma") && c.avx;
    c.avx2 = has("avx2") && c.avx;
    c.avx512 = has("avx512f") && c.avx;

    // check_cpu_caps_override(): GALLIUM_NOSSE, then each override value clears one level...
    if (nosse) c.sse = false;
    c.override_caps = override_caps ? override_caps : "";
    const std::string& o = c.override_caps;
    if (o == "nosse")
        c.sse = false;
    else if (o == "sse")
        c.sse2 = false;
    else if (o == "sse2")
        c.sse3 = false;
    else if (o == "sse3")
        c.ssse3 = false;
    else if (o == "ssse3")
        c.sse41 = false;
    else if (o == "sse4.1")
        c.avx = false;
    else if (o == "avx")
        c.avx512 = false;
    else if (!o.empty())
        c.warning = "GALLIUM_OVERRIDE_CPU_CAPS='" + o +
                    "' is not a value Mesa 22.3 recognises (nosse, sse, sse2, sse3, ssse3, sse4.1, avx): ignored";
    // ...and every level implies the ones below it.
    c.sse2 &= c.sse;
    c.sse3 &= c.sse2;
    c.ssse3 &= c.sse3;
    c.sse41 &= c.ssse3;
    c.avx &= c.sse41;
    c.avx2 &= c.avx;
    c.f16c &= c.avx;
    c.fma &= c.avx;
    c.avx512 &= c.avx;

    // check_max_vector_bits() gives 512 with AVX-512, 256 with AVX, else 128; llvmpipe
    // (lp_build_init_native_width) caps it at 256, then LP_NATIVE_VECTOR_WIDTH replaces it, read with
    // strtol(…, 0) and ignored when it has no digits (measured: "0x80" → 128, "256x" → 256, "abc" → default).
    int max_bits = c.avx512 ? 512 : c.avx ? 256 : 128;
    c.vector_width = std::min(max_bits, 256);
    if (native_vector_width) {
        char* end = nullptr;
        long v = std::strtol(native_vector_width, &end, 0);
        if (end != native_vector_width) c.vector_width = int(v);
    }
    return c;
}

} // namespace

std::string LlvmpipeCaps::cpu_class() const {
    // What changes the code llvmpipe generates: the instruction set level, FMA (llvm.fmuladd
    // contracts a*b+c into one rounding), F16C (half conversions, and shaderFloat16 itself), and the
    // vector width. AVX-512 is left out on purpose: llvmpipe caps the width at 256 bits and, on this
    // machine (Mesa 22.3, LLVM 15), renders with AVX-512 on and off (GALLIUM_OVERRIDE_CPU_CAPS=avx)
    // are bit-identical, ci suite included, so it would only split golden sets for nothing.
    std::string isa = avx2    ? "avx2"
                      : avx   ? "avx"
                      : sse41 ? "sse4.1"
                      : ssse3 ? "ssse3"
                      : sse3  ? "sse3"
                      : sse2  ? "sse2"
                      : sse   ? "sse"
                              : "nosse";
    if (isa == "nosse") return vector_width == 128 ? isa : isa + "-" + std::to_string(vector_width);
    if (fma) isa += "-fma";
    if (f16c) isa += "-f16c";
    return isa + "-" + std::to_string(vector_width);
}

LlvmpipeCaps llvmpipe_caps_from(const std::string& cpuinfo_flags, const char* override_caps, const char* native_vector_width) {
    return caps_from(cpuinfo_flags, override_caps, native_vector_width, false);
}

LlvmpipeCaps llvmpipe_caps() {
    std::ifstream f("/proc/cpuinfo");
    std::stringstream ss;
    ss << f.rdbuf();
    return caps_from(ss.str(), std::getenv("GALLIUM_OVERRIDE_CPU_CAPS"), std::getenv("LP_NATIVE_VECTOR_WIDTH"),
                     mesa_bool(std::getenv("GALLIUM_NOSSE")));
}

} // namespace iblcheck
