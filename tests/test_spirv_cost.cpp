// The SPIR-V instruction-counting pass (renderers/vulkan/spirv_cost.h) on small compute shaders
// run on lavapipe with validation on. Expected counts come from SPIRV-Tools' disassembly of the
// un-instrumented module (lines per block), not from the pass, and the instrumented module must
// pass spirv-val and compute what the original computes.
#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>

#include "kernel/errors.h"
#include "renderers/vulkan/context.h"
#include "renderers/vulkan/spirv_cost.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_spirv_cost {

namespace {
// Compile options that instrument the shader (spirv_cost.h).
const vk::CompileOptions kCounted = [] {
    vk::CompileOptions o;
    o.count_instructions = true;
    return o;
}();

fs::path temp_dir() {
    static fs::path p = [] {
        fs::path d = testutil::temp_dir("test_spirv_cost");
        // A private SPIR-V cache: earlier runs' entries cannot answer for this one.
        setenv("IBLCHECK_CACHE_DIR", (d / "cache").c_str(), 1);
        return d;
    }();
    return p;
}

vk::Context& context() {
    static vk::Context ctx({"", true});
    return ctx;
}

// Compiles `source` (GLSL) un-instrumented.
vk::CompiledShader compile(const std::string& name, const std::string& source) {
    fs::path p = temp_dir() / (name + ".comp");
    std::ofstream(p) << source;
    return vk::compile_compute_shader_file(p);
}

std::string validate(const std::vector<uint32_t>& spirv) {
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string messages;
    tools.SetMessageConsumer(
        [&](spv_message_level_t, const char*, const spv_position_t&, const char* m) { messages += std::string(m) + "\n"; });
    return tools.Validate(spirv) ? "" : "invalid: " + messages;
}

// Lines per block of each function in SPIRV-Tools' disassembly: what follows each OpLabel up to
// the next OpLabel or OpFunctionEnd (OpLine/OpNoLine excepted). Independent of the pass's parser.
std::vector<std::vector<uint64_t>> disassembled_block_sizes(const std::vector<uint32_t>& spirv) {
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string text;
    EXPECT_TRUE(tools.Disassemble(spirv, &text, SPV_BINARY_TO_TEXT_OPTION_NO_HEADER));
    std::vector<std::vector<uint64_t>> functions;
    std::istringstream in(text);
    std::string line;
    bool in_block = false;
    while (std::getline(in, line)) {
        auto has = [&](const char* op) {
            size_t at = line.find(op);
            return at != std::string::npos && (at + std::strlen(op) == line.size() || line[at + std::strlen(op)] == ' ');
        };
        if (has("OpFunction")) {
            functions.emplace_back();
            in_block = false;
        } else if (has("OpFunctionEnd")) {
            in_block = false;
        } else if (has("OpLabel")) {
            functions.back().push_back(0);
            in_block = true;
        } else if (in_block && !has("OpLine") && !has("OpNoLine") && line.find_first_not_of(' ') != std::string::npos) {
            ++functions.back().back();
        }
    }
    return functions;
}

struct Run {
    uint64_t count = 0;
    std::vector<uint32_t> data; // the data buffer after the dispatch
};

// Dispatches `shader` (instrumented when `counted`) over `groups` workgroups with `data` at
// binding 0 and `push` as a uint push constant.
Run run(const std::vector<uint32_t>& spirv, bool counted, std::vector<uint32_t> data, uint32_t push, uint32_t groups = 1) {
    vk::Context& ctx = context();
    vk::CompiledShader shader;
    shader.spirv = spirv;
    shader.counts_instructions = counted;
    vk::ComputePipeline p(ctx, shader, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
    vk::Buffer buf = ctx.create_buffer(data.size() * 4);
    std::memcpy(buf.mapped, data.data(), data.size() * 4);
    Run r;
    if (counted) {
        r.count = vk::count_dispatch_instructions(ctx, p, {vk::Binding::storage_buffer(0, buf)}, &push, 4, groups);
    } else {
        ctx.submit([&](VkCommandBuffer cmd) {
            p.dispatch(cmd, {vk::Binding::storage_buffer(0, buf)}, &push, 4, groups);
            vk::Context::barrier(cmd);
        });
    }
    r.data.assign(buf.as<uint32_t>(), buf.as<uint32_t>() + data.size());
    EXPECT_EQ(ctx.validation_errors(), 0) << (ctx.validation_messages().empty() ? "" : ctx.validation_messages()[0]);
    return r;
}

// Instruments, validates, and checks that the instrumented module writes what the original does.
std::vector<uint32_t> instrument_checked(const vk::CompiledShader& original, const std::vector<uint32_t>& data, uint32_t push,
                                         uint32_t groups = 1) {
    std::vector<uint32_t> counted = vk::instrument_instruction_count(original.spirv);
    EXPECT_EQ(validate(original.spirv), "");
    EXPECT_EQ(validate(counted), "");
    EXPECT_EQ(run(original.spirv, false, data, push, groups).data, run(counted, true, data, push, groups).data);
    // The pass's own per-block counts agree with the disassembly.
    auto mine = vk::block_instruction_counts(original.spirv);
    auto theirs = disassembled_block_sizes(original.spirv);
    EXPECT_EQ(mine.size(), theirs.size());
    for (size_t f = 0; f < std::min(mine.size(), theirs.size()); ++f)
        EXPECT_EQ(std::vector<uint64_t>(mine[f].begin(), mine[f].end()), theirs[f]) << "function " << f;
    return counted;
}

// n[i] iterations in invocation i (64 a workgroup), so the loop's trip count is data-dependent.
const char* kLoop = R"(#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Data { uint n[64]; float v[64]; } d;
layout(push_constant) uniform P { uint unused; } pc;
void main() {
    uint i = gl_LocalInvocationID.x;
    float acc = 0.0;
    for (uint k = 0u; k < d.n[i]; ++k) acc = acc * 0.5 + float(k);
    d.v[i] = acc;
}
)";

} // namespace

TEST(SpirvCost, LoopCountGrowsExactlyLinearlyWithTheBodysStaticCount) {
    vk::CompiledShader s = compile("loop", kLoop);
    // glslang: entry, loop header, condition, body, continue, merge (the disassembly shows it).
    auto blocks = disassembled_block_sizes(s.spirv);
    ASSERT_EQ(blocks.size(), 1u);
    ASSERT_EQ(blocks[0].size(), 6u);
    const auto& b = blocks[0];
    const uint64_t slope = b[1] + b[2] + b[3] + b[4]; // one more trip: header + condition + body + continue
    const uint64_t base = b[0] + b[1] + b[2] + b[5];  // no trip: entry, the failing test, merge
    EXPECT_EQ(slope, 19u);                            // this glslang's output: 2 + 6 + 7 + 4 (the disassembly, by hand)
    EXPECT_EQ(base, 22u);                             // 9 + 2 + 6 + 5

    std::vector<uint32_t> data(128, 0);
    auto counted = instrument_checked(s, data, 0);
    for (uint32_t n : {0u, 1u, 2u, 7u, 100u, 1000u}) {
        std::fill(data.begin(), data.begin() + 64, n);
        EXPECT_EQ(run(counted, true, data, 0).count, 64 * (base + slope * n)) << "n = " << n;
    }
    // A different trip count per invocation: the total is the sum of the invocations'.
    std::iota(data.begin(), data.begin() + 64, 0u);
    EXPECT_EQ(run(counted, true, data, 0).count, 64 * base + slope * (63 * 64 / 2));
    // Two workgroups (both read the same n[]): twice the count.
    EXPECT_EQ(run(counted, true, data, 0, 2).count, 2 * (64 * base + slope * (63 * 64 / 2)));
}

TEST(SpirvCost, NestedLoopsCountEveryTripAndTheTotalPasses32Bits) {
    vk::CompiledShader s = compile("nested", R"(#version 460
layout(local_size_x = 1) in;
layout(binding = 0, std430) buffer Data { uint n[64]; float v[64]; } d;
layout(push_constant) uniform P { uint unused; } pc;
void main() {
    float acc = 0.0;
    for (uint o = 0u; o < d.n[0]; ++o)
        for (uint k = 0u; k < d.n[1]; ++k) acc = acc * 0.5 + float(k);
    d.v[0] = acc;
}
)");
    auto blocks = disassembled_block_sizes(s.spirv);
    ASSERT_EQ(blocks.size(), 1u);
    // entry; outer header, condition, body; inner header, condition, body, continue, merge;
    // outer continue; merge
    ASSERT_EQ(blocks[0].size(), 11u);
    const auto& b = blocks[0];
    auto expected = [&](uint64_t outer, uint64_t inner) {
        return b[0] + (outer + 1) * (b[1] + b[2]) +
               outer * (b[3] + (inner + 1) * (b[4] + b[5]) + inner * (b[6] + b[7]) + b[8] + b[9]) + b[10];
    };
    std::vector<uint32_t> data(128, 0);
    auto counted = instrument_checked(s, data, 0);
    for (auto [outer, inner] : {std::pair{0u, 9u}, std::pair{3u, 5u}, std::pair{30u, 2000u}}) {
        data[0] = outer;
        data[1] = inner;
        EXPECT_EQ(run(counted, true, data, 0).count, expected(outer, inner)) << outer << " x " << inner;
    }
    // lavapipe (gallivm's loop limiter) ends every loop of an invocation once it has made 65535
    // trips in all, so no invocation here gets near 2^32 instructions; the count is what ran.
    data[0] = 40;
    data[1] = 2000;
    uint64_t capped = run(counted, true, data, 0).count;
    EXPECT_LT(capped, expected(40, 2000));
    EXPECT_GT(capped, expected(32, 2000));

    // The total passes 2^32 without wrapping: 64 workgroups x 64 invocations x 60000 trips.
    vk::CompiledShader loop = compile("loop", kLoop);
    auto l = disassembled_block_sizes(loop.spirv)[0];
    std::fill(data.begin(), data.begin() + 64, 60000u);
    uint64_t all = run(vk::instrument_instruction_count(loop.spirv), true, data, 0, 64).count;
    EXPECT_EQ(all, 64 * 64 * (l[0] + l[1] + l[2] + l[5] + 60000 * (l[1] + l[2] + l[3] + l[4])));
    EXPECT_GT(all, uint64_t(1) << 32);
}

TEST(SpirvCost, IfElseCountsTheBranchTaken) {
    vk::CompiledShader s = compile("branch", R"(#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Data { uint n[64]; float v[64]; } d;
layout(push_constant) uniform P { uint threshold; } pc;
void main() {
    uint i = gl_LocalInvocationID.x;
    if (d.n[i] > pc.threshold) {
        d.v[i] = 1.0;
    } else {
        d.v[i] = float(i) * 2.0 + 3.0;
        d.v[i] += sqrt(d.v[i]);
    }
}
)");
    auto blocks = disassembled_block_sizes(s.spirv);
    ASSERT_EQ(blocks.size(), 1u);
    ASSERT_EQ(blocks[0].size(), 4u); // entry, then, else, merge
    const auto& b = blocks[0];
    const uint64_t then_path = b[0] + b[1] + b[3], else_path = b[0] + b[2] + b[3];
    ASSERT_NE(then_path, else_path);
    std::vector<uint32_t> data(128, 0);
    std::iota(data.begin(), data.begin() + 64, 0u);
    auto counted = instrument_checked(s, data, 5);
    EXPECT_EQ(run(counted, true, data, 100).count, 64 * else_path);           // nobody above 100
    EXPECT_EQ(run(counted, true, data, 0).count, 63 * then_path + else_path); // all but n = 0
    EXPECT_EQ(run(counted, true, data, 5).count, 58 * then_path + 6 * else_path);
}

TEST(SpirvCost, EarlyReturnCountsOnlyTheBlocksExecuted) {
    // Two returns from the entry point: each flushes its own count.
    vk::CompiledShader s = compile("early", R"(#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Data { uint n[64]; float v[64]; } d;
layout(push_constant) uniform P { uint live; } pc;
void main() {
    uint i = gl_LocalInvocationID.x;
    if (i >= pc.live) return;
    float x = float(d.n[i]);
    d.v[i] = x * x + exp(x) - 1.0;
}
)");
    auto blocks = disassembled_block_sizes(s.spirv);
    ASSERT_EQ(blocks.size(), 1u);
    ASSERT_EQ(blocks[0].size(), 3u); // entry, the return, the rest
    const auto& b = blocks[0];
    const uint64_t early = b[0] + b[1], late = b[0] + b[2];
    ASSERT_LT(early, late);
    std::vector<uint32_t> data(128, 1);
    auto counted = instrument_checked(s, data, 10);
    for (uint32_t active : {0u, 1u, 10u, 64u})
        EXPECT_EQ(run(counted, true, data, active).count, active * late + (64 - active) * early) << active;
}

TEST(SpirvCost, CalledFunctionsCountTheirBlocksPerCall) {
    vk::CompiledShader s = compile("calls", R"(#version 460
layout(local_size_x = 1) in;
layout(binding = 0, std430) buffer Data { uint n[64]; float v[64]; } d;
layout(push_constant) uniform P { uint calls; } pc;
float twice_plus_one(float x) { return x * 2.0 + 1.0; }
void main() {
    float x = 0.0;
    for (uint k = 0u; k < pc.calls; ++k) x = twice_plus_one(x);
    d.v[0] = x;
}
)");
    auto blocks = disassembled_block_sizes(s.spirv);
    ASSERT_EQ(blocks.size(), 2u); // main, then the function
    ASSERT_EQ(blocks[0].size(), 6u);
    ASSERT_EQ(blocks[1].size(), 1u);
    const auto& m = blocks[0];
    const uint64_t per_call = m[1] + m[2] + m[3] + m[4] + blocks[1][0];
    std::vector<uint32_t> data(128, 0);
    auto counted = instrument_checked(s, data, 3);
    uint64_t zero = run(counted, true, data, 0).count;
    EXPECT_EQ(zero, m[0] + m[1] + m[2] + m[5]);
    EXPECT_EQ(run(counted, true, data, 9).count, zero + 9 * per_call);
}

TEST(SpirvCost, InstrumentedShaderIsCachedUnderItsOwnKey) {
    fs::path p = temp_dir() / "keyed.comp";
    std::ofstream(p) << kLoop;
    auto plain = vk::compile_compute_shader_file(p);
    auto counted = vk::compile_compute_shader_file(p, {}, kCounted);
    EXPECT_NE(plain.source_hash, counted.source_hash);
    EXPECT_FALSE(plain.counts_instructions);
    EXPECT_TRUE(counted.counts_instructions);
    EXPECT_EQ(counted.spirv, vk::instrument_instruction_count(plain.spirv));
    auto again = vk::compile_compute_shader_file(p, {}, kCounted);
    EXPECT_TRUE(again.from_cache);
    EXPECT_TRUE(again.counts_instructions);
    EXPECT_EQ(again.spirv, counted.spirv);
    EXPECT_EQ(vk::compile_compute_shader_file(p).spirv, plain.spirv);
}

TEST(SpirvCost, ShaderUsingTheCounterBindingIsACompileError) {
    vk::CompiledShader s = compile("taken", R"(#version 460
layout(local_size_x = 1) in;
layout(binding = 15, std430) buffer Data { float v[]; } d;
void main() { d.v[0] = 1.0; }
)");
    EXPECT_THROW(vk::instrument_instruction_count(s.spirv), ShaderCompileError);
    EXPECT_THROW(vk::instrument_instruction_count({1, 2, 3}), Error);
}
} // namespace test_spirv_cost
