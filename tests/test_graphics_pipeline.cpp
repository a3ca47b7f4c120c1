// Graphics pipelines and offscreen MSAA targets (renderers/vulkan/graphics_pipeline.h, issue 18) on
// lavapipe with validation on: a draw lands where its vertices say, the resolve averages the
// samples a fragment's coverage mask lets through, the depth test keeps the nearest, and the
// instruction-counting pass (spirv_cost.h) counts a draw's fragments, discarded ones included.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "kernel/errors.h"
#include "renderers/vulkan/graphics_pipeline.h"
#include "renderers/vulkan/spirv_cost.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_graphics_pipeline {

namespace {

fs::path temp_dir() {
    static fs::path p = [] {
        fs::path d = testutil::temp_dir("test_graphics");
        setenv("IBLCHECK_CACHE_DIR", (d / "cache").c_str(), 1); // a private SPIR-V cache
        return d;
    }();
    return p;
}

vk::Context& context() {
    static vk::Context ctx({"", true});
    return ctx;
}

vk::CompiledShader compile(const std::string& file, const std::string& source, bool counted = false) {
    fs::path p = temp_dir() / file;
    std::ofstream(p) << source;
    vk::CompileOptions o;
    o.count_instructions = counted;
    return vk::compile_shader_file(p, {}, o);
}

// A full-target quad (triangle strip) at depth push.depth; the fragment shader discards pixels left
// of x = push.discard_below, writes push.color and lets through the samples in push.mask.
const char* kQuadVert = R"(#version 460
layout(push_constant) uniform P { vec4 color; float depth; uint mask; float discard_below; } pc;
void main() {
    vec2 c = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1)) * 2.0 - 1.0;
    gl_Position = vec4(c, pc.depth, 1.0);
}
)";
const char* kMaskFrag = R"(#version 460
layout(push_constant) uniform P { vec4 color; float depth; uint mask; float discard_below; } pc;
layout(location = 0) out vec4 color;
void main() {
    if (gl_FragCoord.x < pc.discard_below) discard;
    color = pc.color;
    gl_SampleMask[0] = int(pc.mask);
}
)";
struct Push {
    float color[4];
    float depth;
    uint32_t mask;
    float discard_below;
};

struct Fixture {
    vk::TargetFormat format;
    vk::CompiledShader vs, fs;
    std::unique_ptr<vk::GraphicsPipeline> pipeline;
    explicit Fixture(bool counted = false) {
        vs = compile("quad.vert", kQuadVert, counted);
        fs = compile("mask.frag", kMaskFrag, counted);
        vk::GraphicsPipelineDesc d;
        d.vertex = &vs;
        d.fragment = &fs;
        d.push_constant_bytes = sizeof(Push);
        d.target = format;
        pipeline = std::make_unique<vk::GraphicsPipeline>(context(), d);
    }
    // Draws each push in order into a fresh 8x8 target and returns the resolved RGBA.
    std::vector<float> draw(const std::vector<Push>& pushes, std::vector<vk::Binding> bindings = {}) {
        vk::OffscreenTarget target(context(), 8, 8, format);
        vk::Buffer out = context().create_buffer(8 * 8 * 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        context().submit([&](VkCommandBuffer cmd) {
            target.begin(cmd, {0, 0, 0, 0});
            for (const Push& p : pushes) pipeline->draw(cmd, bindings, &p, sizeof p, 4, 1);
            target.end(cmd);
            target.copy_resolved(cmd, out);
        });
        const float* f = out.as<float>();
        return std::vector<float>(f, f + 8 * 8 * 4);
    }
};

void expect_no_validation_errors() {
    auto& ctx = context();
    EXPECT_EQ(ctx.validation_errors(), 0) << (ctx.validation_messages().empty() ? "" : ctx.validation_messages()[0]);
}

} // namespace

TEST(GraphicsPipeline, TheDeviceDrawsFourSampleTargets) {
    const vk::DeviceInfo& info = context().info();
    EXPECT_TRUE(info.graphics);
    EXPECT_TRUE(info.standard_sample_locations);
    EXPECT_TRUE(info.color_sample_counts & VK_SAMPLE_COUNT_4_BIT);
    EXPECT_NO_THROW(vk::require_target_support(context(), vk::TargetFormat{}));
    vk::TargetFormat eight;
    eight.samples = VK_SAMPLE_COUNT_64_BIT;
    EXPECT_THROW(vk::require_target_support(context(), eight), EnvironmentError);
}

TEST(GraphicsPipeline, ResolveAveragesTheSamplesTheMaskLetsThrough) {
    Fixture f;
    for (uint32_t mask : {0xFu, 0x1u, 0x3u, 0x7u, 0x0u}) {
        auto px = f.draw({Push{{1, 0.5f, 0.25f, 1}, 0.5f, mask, 0}});
        float expected = float(__builtin_popcount(mask)) / 4.0f;
        for (int i = 0; i < 64; ++i) {
            ASSERT_FLOAT_EQ(px[4 * size_t(i) + 0], expected) << "mask " << mask << " pixel " << i;
            ASSERT_FLOAT_EQ(px[4 * size_t(i) + 1], 0.5f * expected) << "mask " << mask;
            ASSERT_FLOAT_EQ(px[4 * size_t(i) + 3], expected) << "mask " << mask;
        }
    }
    expect_no_validation_errors();
}

TEST(GraphicsPipeline, DepthTestKeepsTheNearestPerSample) {
    Fixture f;
    // Far red on every sample, then near green on samples 0 and 1, then farther blue everywhere:
    // half green, half red; blue loses everywhere.
    auto px = f.draw({Push{{1, 0, 0, 1}, 0.6f, 0xF, 0}, Push{{0, 1, 0, 1}, 0.2f, 0x3, 0}, Push{{0, 0, 1, 1}, 0.9f, 0xF, 0}});
    EXPECT_FLOAT_EQ(px[0], 0.5f);
    EXPECT_FLOAT_EQ(px[1], 0.5f);
    EXPECT_FLOAT_EQ(px[2], 0.0f);
    expect_no_validation_errors();
}

TEST(GraphicsPipeline, InstructionCountCoversEveryFragmentDiscardedOrNot) {
    Fixture plain, counted(true);
    ASSERT_TRUE(counted.pipeline->counts_instructions());
    if (!context().info().int64_atomics || !context().info().graphics_stores) GTEST_SKIP() << "device cannot count";
    // Same image with and without the counter.
    Push keep{{1, 1, 1, 1}, 0.5f, 0xF, 0}, half{{1, 1, 1, 1}, 0.5f, 0xF, 4}, none{{1, 1, 1, 1}, 0.5f, 0xF, 8},
        clipped{{1, 1, 1, 1}, 2.0f, 0xF, 0}; // depth 2: outside the clip volume, no fragment
    auto count = [&](const Push& p, std::vector<float>* image) {
        vk::Buffer total = context().create_buffer(8);
        auto px = counted.draw({p}, {vk::Binding::storage_buffer(vk::kCostBinding, total)});
        if (image) *image = px;
        return *total.as<uint64_t>();
    };
    std::vector<float> counted_image;
    const uint64_t all = count(keep, &counted_image);
    EXPECT_EQ(counted_image, plain.draw({keep}));
    const uint64_t left_discarded = count(half, nullptr), all_discarded = count(none, nullptr);
    // The vertex stage alone: how many vertex invocations a strip of 4 takes is the driver's choice.
    const uint64_t vertices = count(clipped, nullptr);
    ASSERT_GT(vertices, 0u);
    // 64 fragments run the same path each; discarded ones a shorter one that still counts
    // (OpKill flushes the counter): a whole number per fragment, neither zero nor the full path's.
    ASSERT_GT(all, all_discarded);
    ASSERT_GT(all_discarded, vertices);
    ASSERT_EQ((all - vertices) % 64, 0u) << all << " " << vertices;
    ASSERT_EQ((all_discarded - vertices) % 64, 0u) << all_discarded << " " << vertices;
    const uint64_t kept = (all - vertices) / 64, dropped = (all_discarded - vertices) / 64;
    EXPECT_LT(dropped, kept);
    EXPECT_EQ(left_discarded, vertices + 32 * kept + 32 * dropped);
    EXPECT_EQ(count(keep, nullptr), all); // deterministic
    expect_no_validation_errors();
}

TEST(ShaderCompiler, StageComesFromTheExtension) {
    EXPECT_NO_THROW(compile("ok.vert", kQuadVert));
    EXPECT_NO_THROW(compile("ok.frag", kMaskFrag));
    EXPECT_THROW(compile("bad.glsl", kQuadVert), ShaderCompileError);
    // A fragment shader compiled as a vertex shader fails with the file named.
    try {
        compile("wrong.vert", kMaskFrag);
        FAIL() << "no error";
    } catch (const ShaderCompileError& e) {
        EXPECT_NE(std::string(e.what()).find("wrong.vert"), std::string::npos) << e.what();
    }
}

TEST(GpuTimer, ComputePassAfterADrawIsTimedAroundTheDispatch) {
    // On lavapipe a timestamp written after any render pass waits in llvmpipe's bins until a later
    // flushing timestamp: the begin of a compute pass then resolved after the dispatch and a
    // dispatch of tens of milliseconds read ~0.01 ms (context.h, GpuTimer). A draw, then a busy
    // dispatch (4096 invocations x 20000 iterations: >= 10 ms on any CPU, longer under load).
    Fixture f;
    f.draw({Push{{1, 1, 1, 1}, 0.5f, 0xF, 0}});
    fs::path p = temp_dir() / "busy.comp";
    std::ofstream(p) << R"(#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer B { float v[]; } b;
void main() {
    float x = float(gl_GlobalInvocationID.x);
    for (int i = 0; i < 20000; ++i) x = fract(x * 1.0001 + 0.37);
    b.v[gl_GlobalInvocationID.x] = x;
}
)";
    vk::ComputePipeline busy(context(), vk::compile_compute_shader_file(p), {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 0);
    vk::Buffer out = context().create_buffer(4096 * 4);
    std::vector<vk::Binding> b = {vk::Binding::storage_buffer(0, out)};
    vk::GpuTimer timer(context(), 1);
    context().submit([&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        busy.warm_up(cmd, b, nullptr, 0);
        timer.begin(cmd, "busy");
        busy.dispatch(cmd, b, nullptr, 0, 64);
        timer.end(cmd);
    });
    auto r = timer.results();
    ASSERT_EQ(r.size(), 1u);
    EXPECT_GT(r[0].second, 1.0) << "ms";
    expect_no_validation_errors();
}
} // namespace test_graphics_pipeline
