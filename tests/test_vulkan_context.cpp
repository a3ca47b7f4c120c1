// The Vulkan plumbing on lavapipe: a compute shader checked value by value (with validation on and
// no validation error allowed), fp16 arithmetic as the driver does it, the run-time compiler's
// include/define/cache behaviour (a damaged cache entry included) and its error path, and
// `iblcheck doctor` without a driver.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

#include "kernel/errors.h"
#include "renderers/option_table.h"
#include "renderers/vulkan/context.h"
#include "renderers/vulkan/fp16_emulation.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_vulkan_context {

namespace {

using namespace iblcheck::testutil;

// Runs a shell command, returns its exit status and output (stdout + stderr).

std::vector<float> run_shader(vk::Context& ctx, const vk::CompiledShader& shader, uint32_t n) {
    vk::Buffer buf = ctx.create_buffer(n * 4);
    vk::ComputePipeline p(ctx, shader, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
    ctx.submit([&](VkCommandBuffer cmd) {
        p.dispatch(cmd, {vk::Binding::storage_buffer(0, buf)}, &n, 4, (n + 63) / 64);
        vk::Context::barrier(cmd);
    });
    const float* f = buf.as<float>();
    return std::vector<float>(f, f + n);
}

} // namespace

TEST(VulkanContext, PicksLavapipeAndReportsVersions) {
    vk::Context ctx({"", true});
    EXPECT_EQ(ctx.info().driver_name, "llvmpipe");
    EXPECT_FALSE(ctx.info().mesa_version.empty()) << ctx.info().driver_info;
    EXPECT_FALSE(ctx.info().llvm_version.empty()) << ctx.info().driver_info;
    EXPECT_TRUE(ctx.info().timestamps);
    EXPECT_TRUE(ctx.info().shader_float16);
}

TEST(VulkanContext, UnknownDeviceIsAnEnvironmentErrorListingDevices) {
    try {
        vk::Context ctx({"no-such-gpu-name", false});
        FAIL() << "expected EnvironmentError";
    } catch (const EnvironmentError& e) {
        EXPECT_NE(std::string(e.what()).find("llvmpipe"), std::string::npos) << e.what();
    }
}

TEST(VulkanCompute, ComputesValuesWithIncludesAndDefines) {
    fs::path dir = temp_dir("compute");
    // A private SPIR-V cache, so what earlier runs cached cannot answer for this one.
    setenv("IBLCHECK_CACHE_DIR", (dir / "cache").c_str(), 1);
    write_file(dir / "square.glsl", "float square(float x) { return x * x; }\n");
    write_file(dir / "values.comp", R"(#version 460
#include "square.glsl"
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Out { float v[]; } o;
layout(push_constant) uniform P { uint n; } pc;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < pc.n) o.v[i] = square(float(i)) + OFFSET;
}
)");
    vk::Context ctx({"", true});
    auto shader = vk::compile_compute_shader_file(dir / "values.comp", {{"OFFSET", "0.5"}});
    auto v = run_shader(ctx, shader, 1000);
    for (uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], float(i) * float(i) + 0.5f) << "at " << i;
    EXPECT_EQ(ctx.validation_errors(), 0) << (ctx.validation_messages().empty() ? "" : ctx.validation_messages()[0]);

    // Same source + defines: the SPIR-V comes from the cache with the same key; another define
    // gives another key.
    auto again = vk::compile_compute_shader_file(dir / "values.comp", {{"OFFSET", "0.5"}});
    EXPECT_TRUE(again.from_cache);
    EXPECT_EQ(again.source_hash, shader.source_hash);
    auto other = vk::compile_compute_shader_file(dir / "values.comp", {{"OFFSET", "1.5"}});
    EXPECT_NE(other.source_hash, shader.source_hash);
    EXPECT_EQ(run_shader(ctx, other, 4)[3], 10.5f);

    // Editing an included file changes the key (no stale SPIR-V after a shader edit).
    write_file(dir / "square.glsl", "float square(float x) { return x * x * 2.0; }\n");
    auto edited = vk::compile_compute_shader_file(dir / "values.comp", {{"OFFSET", "0.5"}});
    EXPECT_FALSE(edited.from_cache);
    EXPECT_EQ(run_shader(ctx, edited, 4)[3], 18.5f);
    fs::remove_all(dir);
}

TEST(VulkanCompute, Float16IsTrueHalfPrecisionOnThisDriver) {
    // DEVELOPERS.md: lavapipe computes float16_t as fp16 (1 + 1e-4 = 1, 300·300 = inf): the
    // precision=mediump variant relies on it.
    fs::path dir = temp_dir("fp16");
    write_file(dir / "half.comp", R"(#version 460
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Out { float v[]; } o;
layout(push_constant) uniform P { uint n; } pc;
void main() {
    if (gl_GlobalInvocationID.x != 0u) return;
    float16_t one = float16_t(1.0) + float16_t(float(pc.n) * 1e-7);  // 1 + 1e-4 for n = 1000
    float16_t big = float16_t(300.0 + float(pc.n) * 0.0);
    o.v[0] = float(one);
    o.v[1] = float(big * big);
}
)");
    vk::Context ctx({"", true});
    auto v = run_shader(ctx, vk::compile_compute_shader_file(dir / "half.comp"), 1000);
    EXPECT_EQ(v[0], 1.0f);
    EXPECT_TRUE(std::isinf(v[1])) << v[1];
    fs::remove_all(dir);
}

TEST(ShaderCompiler, ErrorNamesFileAndLine) {
    fs::path dir = temp_dir("bad");
    write_file(dir / "bad.comp", "#version 460\nlayout(local_size_x = 1) in;\nvoid main() {\n  float x = undefined_thing;\n}\n");
    try {
        vk::compile_compute_shader_file(dir / "bad.comp");
        FAIL() << "expected ShaderCompileError";
    } catch (const ShaderCompileError& e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("bad.comp:4:"), std::string::npos) << msg;
        EXPECT_NE(msg.find("undefined_thing"), std::string::npos) << msg;
    }
    fs::remove_all(dir);
}

TEST(ShaderCompiler, ACacheFileThatIsNotSpirvIsCompiledAgain) {
    // A cache entry of whole words without the SPIR-V magic number (damaged, or written by
    // something else) is ignored, and the module compiled instead is glslang's alone: before
    // compile_stage_file was split (issue 19), glslang appended it to the damaged words.
    fs::path dir = temp_dir("badcache");
    setenv("IBLCHECK_CACHE_DIR", (dir / "cache").c_str(), 1);
    write_file(dir / "one.comp", "#version 460\nlayout(local_size_x = 1) in;\nvoid main() {}\n");
    auto fresh = vk::compile_compute_shader_file(dir / "one.comp");
    fs::path cached = vk::spirv_cache_entry(fresh.source_hash);
    ASSERT_TRUE(fs::exists(cached));
    write_file(cached, std::string(64, 'x'));
    auto again = vk::compile_compute_shader_file(dir / "one.comp");
    EXPECT_FALSE(again.from_cache);
    EXPECT_EQ(again.spirv, fresh.spirv);
    EXPECT_EQ(vk::validate_spirv(again.spirv), "");
    fs::remove_all(dir);
}

TEST(ShaderCompiler, ADamagedCacheEntryIsCompiledAgainAndReplaced) {
    // Issue 30: an entry with the SPIR-V header intact and damaged words behind it was used as it
    // was: pipeline creation failed with "VkResult -13" on every run and the entry stayed; a
    // changed constant would have rendered another image.
    fs::path dir = temp_dir("corruptcache");
    setenv("IBLCHECK_CACHE_DIR", (dir / "cache").c_str(), 1);
    write_file(dir / "twice.comp", R"(#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Out { float v[]; } o;
layout(push_constant) uniform P { uint n; } pc;
void main() { if (gl_GlobalInvocationID.x < pc.n) o.v[gl_GlobalInvocationID.x] = 2.0 * float(gl_GlobalInvocationID.x); }
)");
    const auto fresh = vk::compile_compute_shader_file(dir / "twice.comp");
    const std::string module(reinterpret_cast<const char*>(fresh.spirv.data()), fresh.spirv.size() * 4);
    const fs::path cached = vk::spirv_cache_entry(fresh.source_hash);
    const std::string entry = read_text(cached);
    ASSERT_EQ(entry.substr(0, module.size()), module);
    vk::Context ctx({"", true});
    // Only the constant 2.0 changed to 3.0; garbage behind the 5-word header.
    std::string garbage = entry;
    std::fill(garbage.begin() + 20, garbage.begin() + std::ptrdiff_t(module.size()), '\xab');
    // OpConstant %float 2.0: the words 0x0004002B, type, id, 0x40000000.
    size_t two = 0;
    for (size_t w = 5; w + 3 < fresh.spirv.size() && !two; ++w)
        if (fresh.spirv[w] == 0x0004002Bu && fresh.spirv[w + 3] == 0x40000000u) two = 4 * (w + 3);
    ASSERT_NE(two, 0u);
    std::string three = entry;
    three[two + 2] = '\x40'; // 0x40400000: 3.0
    for (const std::string& damaged : {three, garbage}) {
        write_file(cached, damaged);
        const auto again = vk::compile_compute_shader_file(dir / "twice.comp");
        EXPECT_FALSE(again.from_cache);
        EXPECT_EQ(again.spirv, fresh.spirv);
        EXPECT_EQ(run_shader(ctx, again, 4)[3], 6.0f);
        // The entry was written again: the next compile reads the whole module from it.
        EXPECT_EQ(read_text(cached), entry);
        EXPECT_TRUE(vk::compile_compute_shader_file(dir / "twice.comp").from_cache);
    }
    fs::remove_all(dir);
}

TEST(ShaderCompiler, EveryPipelineShaderIsReusedFromTheCache) {
    // Every module the renderers compile (plain, and instrumented for the cost count) is read
    // back whole from its entry: none is compiled again on every run.
    fs::path dir = temp_dir("validcache");
    setenv("IBLCHECK_CACHE_DIR", (dir / "cache").c_str(), 1);
    vk::Defines defaults = glsl_defines(shader_selections(OptionMap{}, "mobile"));
    defaults.merge(glsl_defines(shader_selections(OptionMap{}, "sampled"))); // shade_sampled.comp's mip_clamp
    OptionMap fragment;
    fragment.set("shading", "fragment");
    const vk::Defines fragment_defaults = glsl_defines(shader_selections(fragment, "mobile"));
    vk::CompileOptions counted;
    counted.count_instructions = true;
    for (const vk::CompileOptions& options : {vk::CompileOptions{}, counted})
        for (const char* s : {"equirect_to_cube.comp", "downsample_cube.comp", "prefilter_ggx.comp", "sh9_project.comp",
                              "irradiance_cube.comp", "dfg_lut.comp", "encode_storage.comp", "shade_spheres.comp",
                              "shade_sampled.comp", "shade_spheres.vert", "shade_spheres.frag"}) {
            const vk::Defines& d = std::string(s).find(".comp") == std::string::npos ? fragment_defaults : defaults;
            EXPECT_FALSE(vk::compile_shader(s, d, options).from_cache) << s;
            EXPECT_TRUE(vk::compile_shader(s, d, options).from_cache) << s << " (count: " << options.count_instructions << ")";
        }
    fs::remove_all(dir);
}

TEST(ShaderCompiler, AllPipelineShadersCompile) {
    // Every pass of renderers/shaders compiles in its default variant (the option table's defaults).
    vk::Defines defaults = glsl_defines(shader_selections(OptionMap{}, "mobile"));
    defaults.merge(glsl_defines(shader_selections(OptionMap{}, "sampled"))); // shade_sampled.comp's mip_clamp
    for (const char* s :
         {"equirect_to_cube.comp", "downsample_cube.comp", "prefilter_ggx.comp", "sh9_project.comp", "irradiance_cube.comp",
          "dfg_lut.comp", "encode_storage.comp", "shade_spheres.comp", "shade_sampled.comp"}) {
        EXPECT_NO_THROW(vk::compile_compute_shader(s, defaults)) << s;
    }
}

TEST(Doctor, NamesLlvmpipeAndExitsZero) {
    std::string out;
    int rc = run_command(built("iblcheck") + " doctor", out);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("llvmpipe"), std::string::npos) << out;
    EXPECT_NE(out.find("shaderFloat16:   yes"), std::string::npos) << out;
}

TEST(Doctor, StatesTheFp16DecisionTheRendererMakes) {
    // The line comes from choose_fp16_path, the renderer's rule: native here, emulated when
    // llvmpipe targets a CPU without AVX (no F16C, no shaderFloat16). Before issue 15 doctor
    // claimed an fp32 fallback while the renderer refused the variant.
    vk::Context ctx({"", false});
    std::string expected =
        "precision=mediump: " +
        vk::fp16_path_description(vk::choose_fp16_path("auto", ctx.info().shader_float16, ctx.info().device_name));
    std::string out;
    EXPECT_EQ(run_command(built("iblcheck") + " doctor", out), 0) << out;
    EXPECT_NE(out.find(expected + "\n"), std::string::npos) << out;
    EXPECT_NE(out.find("precision=mediump: native float16_t\n"), std::string::npos) << out;
    EXPECT_NE(out.find("llvmpipe cpu:    "), std::string::npos) << out;
    EXPECT_EQ(run_command("GALLIUM_OVERRIDE_CPU_CAPS=sse4.1 " + built("iblcheck") + " doctor", out), 0) << out;
    EXPECT_NE(out.find("shaderFloat16:   no\n"), std::string::npos) << out;
    EXPECT_NE(out.find("precision=mediump: " + vk::fp16_path_description(vk::Fp16Path::emulated) + "\n"), std::string::npos)
        << out;
    EXPECT_NE(out.find("cpu override:    GALLIUM_OVERRIDE_CPU_CAPS=sse4.1"), std::string::npos) << out;
}

TEST(Doctor, WithoutDriverExitsTwoWithAFix) {
    std::string out;
    int rc = run_command("VK_ICD_FILENAMES=/nonexistent VK_DRIVER_FILES=/nonexistent " + std::string(IBLCHECK_BINARY_DIR) +
                             "/iblcheck doctor",
                         out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("no Vulkan driver found"), std::string::npos) << out;
    EXPECT_NE(out.find("scripts/setup.sh"), std::string::npos) << out;
}

TEST(Cli, ShaderCompileErrorExitsTwoWithFileLine) {
    fs::path dir = temp_dir("cli_bad");
    fs::copy(fs::path(IBLCHECK_SOURCE_DIR) / "renderers/shaders", dir / "shaders", fs::copy_options::recursive);
    std::ofstream(dir / "shaders/env_brdf.glsl", std::ios::app) << "\nthis is not glsl;\n";
    std::string out;
    int rc = run_command("IBLCHECK_SHADER_DIR=" + (dir / "shaders").string() + " IBLCHECK_CACHE_DIR=" + dir.string() + " " +
                             built("iblcheck") + " render --scene sphere --env constant:1 --method mobile",
                         out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("env_brdf.glsl:"), std::string::npos) << out;
    fs::remove_all(dir);
}
} // namespace test_vulkan_context
