// llvmpipe's CPU features (kernel/cpu_caps.h): Mesa 22.3's override rules on fixed
// /proc/cpuinfo flags, then the model against Mesa's own GALLIUM_DUMP_CPU output on this machine
// for every override value (through `iblcheck doctor`, which also prints the model's cpu_class).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <sys/wait.h>

#include "kernel/cpu_caps.h"
#include "tests/test_support.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_cpu_caps {

namespace {

using namespace iblcheck::testutil;

// This project's machine (AMD EPYC, `flags` of /proc/cpuinfo, abridged to what matters plus noise).
const char* kEpyc = "fpu vme de pse tsc msr pae mce cx8 apic sep mtrr pge mca cmov pat pse36 clflush mmx fxsr sse sse2 "
                    "ht syscall nx mmxext lm pni pclmulqdq ssse3 fma cx16 pcid sse4_1 sse4_2 movbe popcnt aes xsave avx "
                    "f16c rdrand hypervisor bmi1 avx2 smep bmi2 avx512f avx512dq avx512cd avx512bw avx512vl";
// An Ivy Bridge: AVX and F16C, no AVX2, no FMA.
const char* kIvyBridge = "fpu sse sse2 pni ssse3 sse4_1 sse4_2 popcnt xsave avx f16c";
// A Nehalem: SSE4.2, no AVX.
const char* kNehalem = "fpu sse sse2 pni ssse3 sse4_1 sse4_2 popcnt";

} // namespace

TEST(CpuCaps, ThisMachineUnchanged) {
    LlvmpipeCaps c = llvmpipe_caps_from(kEpyc, nullptr, nullptr);
    EXPECT_TRUE(c.sse && c.sse2 && c.sse3 && c.ssse3 && c.sse41 && c.avx && c.avx2 && c.f16c && c.fma && c.avx512);
    EXPECT_EQ(c.vector_width, 256); // AVX-512 does not widen it: llvmpipe caps it at 256
    EXPECT_EQ(c.override_caps, "");
    EXPECT_EQ(c.warning, "");
    EXPECT_EQ(c.cpu_class(), "avx2-fma-f16c-256");
}

TEST(CpuCaps, EachOverrideClearsItsLevelAndEverythingAbove) {
    struct Case {
        const char* value;
        bool sse, sse2, sse3, ssse3, sse41, avx, avx512;
        int width;
        const char* cls;
    };
    for (const Case& k :
         {Case{"nosse", 0, 0, 0, 0, 0, 0, 0, 128, "nosse"}, Case{"sse", 1, 0, 0, 0, 0, 0, 0, 128, "sse-128"},
          Case{"sse2", 1, 1, 0, 0, 0, 0, 0, 128, "sse2-128"}, Case{"sse3", 1, 1, 1, 0, 0, 0, 0, 128, "sse3-128"},
          Case{"ssse3", 1, 1, 1, 1, 0, 0, 0, 128, "ssse3-128"}, Case{"sse4.1", 1, 1, 1, 1, 1, 0, 0, 128, "sse4.1-128"},
          Case{"avx", 1, 1, 1, 1, 1, 1, 0, 256, "avx2-fma-f16c-256"}}) {
        LlvmpipeCaps c = llvmpipe_caps_from(kEpyc, k.value, nullptr);
        SCOPED_TRACE(k.value);
        EXPECT_EQ(c.override_caps, k.value);
        EXPECT_EQ(c.sse, k.sse);
        EXPECT_EQ(c.sse2, k.sse2);
        EXPECT_EQ(c.sse3, k.sse3);
        EXPECT_EQ(c.ssse3, k.ssse3);
        EXPECT_EQ(c.sse41, k.sse41);
        EXPECT_EQ(c.avx, k.avx);
        // AVX2, F16C and FMA go with AVX (u_cpu_detect.c clears them when AVX is off).
        EXPECT_EQ(c.avx2, k.avx);
        EXPECT_EQ(c.f16c, k.avx);
        EXPECT_EQ(c.fma, k.avx);
        EXPECT_EQ(c.avx512, k.avx512);
        EXPECT_EQ(c.vector_width, k.width);
        EXPECT_EQ(c.cpu_class(), k.cls);
        EXPECT_EQ(c.warning, "");
    }
}

TEST(CpuCaps, UnrecognisedOverrideChangesNothingAndWarns) {
    // Mesa 22.3 knows no "avx2" or "sse4.2": it ignores them (measured: the same caps as unset).
    for (const char* v : {"avx2", "sse4.2", "AVX"}) {
        LlvmpipeCaps c = llvmpipe_caps_from(kEpyc, v, nullptr);
        EXPECT_EQ(c.cpu_class(), "avx2-fma-f16c-256") << v;
        EXPECT_TRUE(c.avx512) << v;
        EXPECT_EQ(c.override_caps, v);
        EXPECT_NE(c.warning.find(std::string("'") + v + "'"), std::string::npos) << c.warning;
    }
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, "", nullptr).warning, ""); // set but empty: nothing to warn about
}

TEST(CpuCaps, NativeVectorWidthOverridesAsMesaParsesIt) {
    // strtol(…, 0): decimal, hex; trailing garbage ignored; no digits: the default.
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "128").vector_width, 128);
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "128").cpu_class(), "avx2-fma-f16c-128");
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "0x80").vector_width, 128);
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "256x").vector_width, 256);
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "abc").vector_width, 256);
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, nullptr, "512").vector_width, 512);
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, "sse4.1", "256").cpu_class(), "sse4.1-256");
    EXPECT_EQ(llvmpipe_caps_from(kEpyc, "nosse", "256").cpu_class(), "nosse-256");
}

TEST(CpuCaps, OlderCpusAndCpuinfoText) {
    EXPECT_EQ(llvmpipe_caps_from(kIvyBridge, nullptr, nullptr).cpu_class(), "avx-f16c-256");
    EXPECT_EQ(llvmpipe_caps_from(kNehalem, nullptr, nullptr).cpu_class(), "sse4.1-128");
    EXPECT_EQ(llvmpipe_caps_from("", nullptr, nullptr).cpu_class(), "nosse");
    // FMA/F16C flags without AVX (an OS that does not save YMM hides avx): Mesa drops them.
    EXPECT_EQ(llvmpipe_caps_from("sse sse2 pni ssse3 sse4_1 fma f16c avx2", nullptr, nullptr).cpu_class(), "sse4.1-128");
    // All of /proc/cpuinfo: the first processor's flags line is used, other lines are not flags.
    std::string text = "processor\t: 0\nmodel name\t: Some CPU with sse in its name avx2\nflags\t\t: " + std::string(kNehalem) +
                       "\n\nprocessor\t: 1\nflags\t\t: " + kEpyc + "\n";
    EXPECT_EQ(llvmpipe_caps_from(text, nullptr, nullptr).cpu_class(), "sse4.1-128");
}

TEST(CpuCaps, AgreesWithMesasOwnDumpOnThisMachine) {
    // GALLIUM_DUMP_CPU makes Mesa print the caps it ended with; the device name carries the vector
    // width; doctor prints the model's cpu_class and whether the device has shaderFloat16, which
    // llvmpipe ties to F16C. Each override value in a fresh process (Mesa reads them once).
    std::ifstream f("/proc/cpuinfo");
    std::stringstream cpuinfo;
    cpuinfo << f.rdbuf();
    std::string bin = built("iblcheck") + " doctor";
    struct Run {
        const char* override_caps;
        const char* width;
    };
    for (const Run& r :
         {Run{nullptr, nullptr}, Run{"nosse", nullptr}, Run{"sse", nullptr}, Run{"sse2", nullptr}, Run{"sse3", nullptr},
          Run{"ssse3", nullptr}, Run{"sse4.1", nullptr}, Run{"avx", nullptr}, Run{"avx2", nullptr}, Run{nullptr, "128"}}) {
        std::string env = "GALLIUM_DUMP_CPU=true ";
        if (r.override_caps) env += std::string("GALLIUM_OVERRIDE_CPU_CAPS=") + r.override_caps + " ";
        if (r.width) env += std::string("LP_NATIVE_VECTOR_WIDTH=") + r.width + " ";
        SCOPED_TRACE(env);
        std::string out;
        ASSERT_EQ(run_command(env + bin, out), 0) << out;
        LlvmpipeCaps model = llvmpipe_caps_from(cpuinfo.str(), r.override_caps, r.width);
        auto mesa = [&](const std::string& cap) {
            std::smatch m;
            if (!std::regex_search(out, m, std::regex("util_cpu_caps\\.has_" + cap + " = ([01])")))
                ADD_FAILURE() << "no has_" << cap << " in Mesa's dump:\n" << out;
            return m.size() > 1 && m[1] == "1";
        };
        EXPECT_EQ(mesa("sse"), model.sse);
        EXPECT_EQ(mesa("sse2"), model.sse2);
        EXPECT_EQ(mesa("sse3"), model.sse3);
        EXPECT_EQ(mesa("ssse3"), model.ssse3);
        EXPECT_EQ(mesa("sse4_1"), model.sse41);
        EXPECT_EQ(mesa("avx"), model.avx);
        EXPECT_EQ(mesa("avx2"), model.avx2);
        EXPECT_EQ(mesa("f16c"), model.f16c);
        EXPECT_EQ(mesa("avx512f"), model.avx512);
        std::smatch m;
        ASSERT_TRUE(std::regex_search(out, m, std::regex("llvmpipe \\(LLVM [0-9.]+, ([0-9]+) bits\\)"))) << out;
        EXPECT_EQ(std::stoi(m[1]), model.vector_width);
        EXPECT_NE(out.find("shaderFloat16:   " + std::string(model.f16c ? "yes" : "no")), std::string::npos) << out;
        EXPECT_NE(out.find("llvmpipe cpu:    " + model.cpu_class() + " "), std::string::npos) << out;
    }
}
} // namespace test_cpu_caps
