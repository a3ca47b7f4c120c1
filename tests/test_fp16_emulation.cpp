// fp16 emulation (issue 15, renderers/vulkan/fp16_emulation.h): the SPIR-V pass on small compute
// shaders (the output validates, keeps no 16-bit float, computes what native float16_t computes on
// this machine and what IEEE fp16 gives on the CPU), and the same without AVX/F16C, where lavapipe
// has no shaderFloat16 (GALLIUM_OVERRIDE_CPU_CAPS=sse4.1, in a child process: Mesa reads the CPU
// caps once per process).
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sys/wait.h>

#include "kernel/errors.h"
#include "renderers/option_table.h"
#include "renderers/vulkan/context.h"
#include "renderers/vulkan/fp16_emulation.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_fp16_emulation {

namespace {

using namespace iblcheck::testutil;

vk::Context& context() {
    static vk::Context ctx({"", true});
    return ctx;
}

// Compiles GLSL text (a private SPIR-V cache, so earlier runs cannot answer), optionally emulated.
vk::CompiledShader compile(const std::string& name, const std::string& glsl, bool emulate) {
    fs::path dir = temp_dir("src");
    setenv("IBLCHECK_CACHE_DIR", (dir / "cache").c_str(), 1);
    std::ofstream(dir / name) << glsl;
    vk::CompileOptions opt;
    opt.emulate_fp16 = emulate;
    vk::CompiledShader s = vk::compile_compute_shader_file(dir / name, {}, opt);
    fs::remove_all(dir);
    return s;
}

// Runs `shader` on `inputs` (binding 0) → `outputs` floats (binding 1); push constant: item count.
std::vector<float> dispatch(const vk::CompiledShader& shader, const std::vector<float>& inputs, uint32_t items, size_t outputs) {
    vk::Context& ctx = context();
    vk::Buffer in = ctx.create_buffer(inputs.size() * 4), out = ctx.create_buffer(outputs * 4);
    std::memcpy(in.mapped, inputs.data(), inputs.size() * 4);
    vk::ComputePipeline p(ctx, shader, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
    ctx.submit([&](VkCommandBuffer cmd) {
        p.dispatch(cmd, {vk::Binding::storage_buffer(0, in), vk::Binding::storage_buffer(1, out)}, &items, 4, (items + 63) / 64);
        vk::Context::barrier(cmd);
    });
    EXPECT_EQ(ctx.validation_errors(), 0) << (ctx.validation_messages().empty() ? "" : ctx.validation_messages()[0]);
    return std::vector<float>(out.as<float>(), out.as<float>() + outputs);
}

// Word-level facts about a module: the Float16 capability and 16-bit float types.
bool has_float16_capability(const std::vector<uint32_t>& m) {
    for (size_t i = 5; i < m.size(); i += m[i] >> 16)
        if ((m[i] & 0xffff) == 17 /*OpCapability*/ && m[i + 1] == 9 /*Float16*/) return true;
    return false;
}
int count_f16_types(const std::vector<uint32_t>& m) {
    int n = 0;
    for (size_t i = 5; i < m.size(); i += m[i] >> 16) n += (m[i] & 0xffff) == 22 /*OpTypeFloat*/ && m[i + 2] == 16;
    return n;
}
int count_op(const std::vector<uint32_t>& m, uint32_t op) {
    int n = 0;
    for (size_t i = 5; i < m.size(); i += m[i] >> 16) n += (m[i] & 0xffff) == op;
    return n;
}
// Each rounding to fp16 the pass adds has one roundEven (GLSL.std.450 instruction 2).
int count_round_even(const std::vector<uint32_t>& m) {
    int n = 0;
    for (size_t i = 5; i < m.size(); i += m[i] >> 16) n += (m[i] & 0xffff) == 12 /*OpExtInst*/ && m[i + 4] == 2;
    return n;
}

// IEEE fp16 on the CPU: the exact result computed in double (exact for + − ×; for ÷ and sqrt one
// rounding to 53 bits, innocuous before rounding to 11 since 53 ≥ 2·11 + 2), rounded once by the
// compiler's conversion to _Float16 (round to nearest even, subnormals kept).
float fp16(double exact) { return float(_Float16(exact)); }

// Operations on pairs of fp16 values: + − × ÷, sqrt|x|, and a 3-component dot product.
constexpr int kOps = 6;
const char* kArithmetic = R"(#version 460
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
layout(local_size_x = 64) in;
layout(binding = 0, std430) readonly buffer In { float v[]; } inp;
layout(binding = 1, std430) writeonly buffer Out { float r[]; } o;
layout(push_constant) uniform P { uint n; } pc;
float16_t half_in(uint k) { return float16_t(inp.v[k]); }
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    float16_t x = half_in(2u * i), y = half_in(2u * i + 1u);
    f16vec3 a = f16vec3(x, y, float16_t(0.25)), b = f16vec3(y, x, x);
    o.r[6u * i + 0u] = float(x + y);
    o.r[6u * i + 1u] = float(x - y);
    o.r[6u * i + 2u] = float(x * y);
    o.r[6u * i + 3u] = float(x / y);
    o.r[6u * i + 4u] = float(sqrt(abs(x)));
    o.r[6u * i + 5u] = float(dot(a, b));
}
)";

// The CPU's fp16 result of op k on (x, y) (the dot product as the pass orders it: each product and
// partial sum rounded).
float cpu_op(int k, float x, float y) {
    switch (k) {
    case 0: return fp16(double(x) + y);
    case 1: return fp16(double(x) - y);
    case 2: return fp16(double(x) * y);
    case 3: return fp16(double(x) / y);
    case 4: return fp16(std::sqrt(std::fabs(double(x))));
    default: return fp16(double(fp16(double(fp16(double(x) * y)) + fp16(double(y) * x))) + fp16(0.25 * x));
    }
}

// Random fp16 values: every sign, exponent −14..15 (normal numbers) and mantissa.
std::vector<float> random_halves(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<float> v(n);
    for (float& f : v) {
        uint16_t bits = uint16_t(rng() & 0xffff);
        if ((bits & 0x7c00) == 0x7c00) bits &= 0xbfff; // no inf/NaN: exponent 31 → 15
        if ((bits & 0x7c00) == 0) bits |= 0x0400;      // no subnormal inputs
        _Float16 h;
        std::memcpy(&h, &bits, 2);
        f = float(h);
    }
    return v;
}

bool same_bits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }
bool same_value(float a, float b) { return same_bits(a, b) || (std::isnan(a) && std::isnan(b)); }

} // namespace

TEST(Fp16EmulationPass, OutputValidatesWithoutAnyFloat16) {
    vk::CompiledShader native = compile("a.comp", kArithmetic, false);
    ASSERT_TRUE(has_float16_capability(native.spirv)); // the input of the pass does use fp16
    ASSERT_EQ(count_f16_types(native.spirv), 1);
    EXPECT_EQ(vk::validate_spirv(native.spirv), "");

    std::vector<uint32_t> m = native.spirv;
    vk::Fp16EmulationStats st;
    ASSERT_TRUE(vk::emulate_fp16(m, &st));
    EXPECT_EQ(vk::validate_spirv(m), "");
    EXPECT_FALSE(has_float16_capability(m));
    EXPECT_EQ(count_f16_types(m), 0);
    EXPECT_EQ(count_op(m, 115 /*OpFConvert*/), 0); // f32→f16 became quantizes, f16→f32 copies
    EXPECT_EQ(count_op(m, 148 /*OpDot*/), 0);
    EXPECT_EQ(st.dots_expanded, 1);
    EXPECT_GE(st.constants, 1); // float16_t(0.25)
    // One conversion in (half_in is one function), + − × ÷ sqrt, the dot product's 3 products
    // and 2 sums.
    EXPECT_EQ(st.rounded, 1 + 5 + 5);
    EXPECT_EQ(count_round_even(m), st.rounded);
    EXPECT_EQ(count_op(m, 116 /*OpQuantizeToF16*/), 0); // lavapipe cannot run it without F16C

    // The compiler applies it when asked, and keys the cache apart.
    vk::CompiledShader emulated = compile("a.comp", kArithmetic, true);
    EXPECT_EQ(emulated.spirv, m);
    EXPECT_NE(emulated.source_hash, native.source_hash);
}

TEST(Fp16EmulationPass, ShadeSpheresMediumpValidatesInEveryVariant) {
    // The shader the option is for, in the variants that use different fp16 code (dominant
    // direction with sqrt, normalisation with smoothstep and a division, the LUT path).
    auto mediump = [](std::map<std::string, std::string> set) {
        OptionMap o;
        o.set("precision", "mediump");
        for (const auto& [k, v] : set) o.set(k, v);
        return glsl_defines(shader_selections(o, "mobile"));
    };
    for (const vk::Defines& d : {mediump({}), mediump({{"dominant_dir", "lagarde"}, {"normalization", "ue4"}}),
                                 mediump({{"dominant_dir", "filament"}, {"env_brdf", "lut"}})}) {
        vk::CompileOptions opt;
        opt.emulate_fp16 = true;
        vk::CompiledShader s = vk::compile_compute_shader("shade_spheres.comp", d, opt);
        EXPECT_EQ(vk::validate_spirv(s.spirv), "");
        EXPECT_FALSE(has_float16_capability(s.spirv));
        EXPECT_EQ(count_f16_types(s.spirv), 0);
        EXPECT_GT(count_round_even(s.spirv), 20);
    }
}

TEST(Fp16EmulationPass, ModuleWithoutFp16IsLeftAlone) {
    vk::CompiledShader highp =
        vk::compile_compute_shader("shade_spheres.comp", glsl_defines(shader_selections(OptionMap{}, "mobile")));
    std::vector<uint32_t> m = highp.spirv;
    EXPECT_FALSE(vk::emulate_fp16(m));
    EXPECT_EQ(m, highp.spirv);
}

TEST(Fp16EmulationPass, RefusesFp16InABuffer) {
    // Widening a buffer member would move every offset after it: refused, not silently wrong.
    const char* glsl = R"(#version 460
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#extension GL_EXT_shader_16bit_storage : require
layout(local_size_x = 1) in;
layout(binding = 0, std430) buffer B { float16_t h[]; } b;
void main() { b.h[0] = b.h[1] * float16_t(2.0); }
)";
    try {
        compile("buf.comp", glsl, true);
        FAIL() << "expected ShaderCompileError";
    } catch (const ShaderCompileError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot be widened"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("buf.comp"), std::string::npos) << e.what();
    }
}

TEST(Fp16EmulationDispatch, KnownValuesAreFp16Results) {
    // 1 + 2^-11 is a tie between 1 and 1 + 2^-10: to even, 1. 65504·2 overflows to inf. 1/3 is
    // 0x3555 = 0.333251953125. 2049 = 2048 + 1 is a tie: 2048. 65519 rounds down to 65504, 65520 up
    // to inf (IEEE's overflow threshold).
    std::vector<float> in = {1.0f, 0x1p-11f, 65504.0f, 2.0f, 1.0f, 3.0f, 2048.0f, 1.0f, 65504.0f, 15.0f, 65504.0f, 16.0f};
    std::vector<float> expect = {1.0f, INFINITY, 0.333251953125f, 2048.0f, 65504.0f, INFINITY};
    const char* glsl = R"(#version 460
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
layout(local_size_x = 64) in;
layout(binding = 0, std430) readonly buffer In { float v[]; } inp;
layout(binding = 1, std430) writeonly buffer Out { float r[]; } o;
layout(push_constant) uniform P { uint n; } pc;
void main() {
    if (gl_GlobalInvocationID.x != 0u) return;
    float16_t h[12];
    for (int k = 0; k < 12; ++k) h[k] = float16_t(inp.v[k]);
    o.r[0] = float(h[0] + h[1]);
    o.r[1] = float(h[2] * h[3]);
    o.r[2] = float(h[4] / h[5]);
    o.r[3] = float(h[6] + h[7]);
    o.r[4] = float(h[8] + h[9]);
    o.r[5] = float(h[10] + h[11]);
}
)";
    std::vector<float> emulated = dispatch(compile("known.comp", glsl, true), in, 1, 6);
    for (size_t k = 0; k < expect.size(); ++k) EXPECT_TRUE(same_bits(emulated[k], expect[k])) << k << ": " << emulated[k];
    if (context().info().shader_float16) {
        std::vector<float> native = dispatch(compile("known.comp", glsl, false), in, 1, 6);
        for (size_t k = 0; k < expect.size(); ++k) EXPECT_TRUE(same_bits(native[k], expect[k])) << k << ": " << native[k];
    }
    // Without the rounding (the same arithmetic in fp32) none of these would hold.
    EXPECT_NE(1.0f + 0x1p-11f, 1.0f);
    EXPECT_FALSE(std::isinf(65504.0f * 2.0f));
}

TEST(Fp16EmulationDispatch, RandomOperandsMatchNativeAndIeeeFp16BitForBit) {
    // 16384 pairs of random normal fp16 values through + − × ÷ sqrt and a dot product: emulated,
    // native (where the driver has shaderFloat16) and the CPU's IEEE fp16 agree bit for bit,
    // overflow to inf and subnormal results included.
    const uint32_t n = 16384;
    std::vector<float> in = random_halves(2 * n, 15);
    std::vector<float> emulated = dispatch(compile("arith.comp", kArithmetic, true), in, n, size_t(n) * kOps);
    bool has_native = context().info().shader_float16;
    std::vector<float> native =
        has_native ? dispatch(compile("arith.comp", kArithmetic, false), in, n, size_t(n) * kOps) : std::vector<float>();
    int mismatches[kOps] = {}, native_mismatches[kOps] = {}, subnormals = 0, overflows = 0;
    for (uint32_t i = 0; i < n; ++i)
        for (int k = 0; k < kOps; ++k) {
            float x = in[2 * i], y = in[2 * i + 1], cpu = cpu_op(k, x, y), e = emulated[size_t(i) * kOps + k];
            overflows += std::isinf(cpu);
            subnormals += cpu != 0 && std::fabs(cpu) < 0x1p-14f;
            if (!same_value(cpu, e) && mismatches[k]++ < 3)
                ADD_FAILURE() << "op " << k << " x=" << x << " y=" << y << ": cpu " << cpu << ", emulated " << e;
            if (has_native && !same_value(native[size_t(i) * kOps + k], e) && native_mismatches[k]++ < 3)
                ADD_FAILURE() << "op " << k << " x=" << x << " y=" << y << ": native " << native[size_t(i) * kOps + k]
                              << ", emulated " << e;
        }
    for (int k = 0; k < kOps; ++k) {
        EXPECT_EQ(mismatches[k], 0) << "op " << k;
        EXPECT_EQ(native_mismatches[k], 0) << "op " << k;
    }
    // The sample reaches both ends of the range, so overflow and subnormal rounding were exercised.
    EXPECT_GT(overflows, 1000);
    EXPECT_GT(subnormals, 1000);
}

TEST(Fp16EmulationDispatch, SameResultsOnACpuWithoutF16c) {
    // Mesa without AVX (hence without F16C and shaderFloat16): the emulated path is the only one,
    // and must still produce IEEE fp16 results. Re-runs this binary's value tests in a child.
    std::string out;
    int rc = run_command("GALLIUM_OVERRIDE_CPU_CAPS=sse4.1 /proc/" + std::to_string(::getpid()) +
                             "/exe --gtest_filter='Fp16EmulationDispatch.KnownValues*:Fp16EmulationDispatch.Random*'",
                         out);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("[  PASSED  ] 2 tests"), std::string::npos) << out;
}
} // namespace test_fp16_emulation
