// The per-pixel passes read the scene and the SH coefficients from uniform buffers, never from
// storage buffers: lavapipe loads a storage buffer one SIMD lane at a time, and the ray-traced
// passes read every sphere for every ray (renderers/mobile/gpu_scene.h has the measurement: the
// ci suite's shading 4x slower). These tests read the compiled SPIR-V, so a pass that goes back to
// a storage buffer, or a scene block whose size the host no longer matches, fails here and not as a
// slow or garbled render.
#include <glslang/SPIRV/spirv.hpp>
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "kernel/errors.h"
#include "renderers/mobile/gpu_scene.h"
#include "renderers/option_table.h"
#include "renderers/vulkan/shader_compiler.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_shading_buffers {

namespace {
// One buffer a module declares at a binding, read from its SPIR-V.
struct BufferBlock {
    bool storage = false;           // a storage buffer (StorageBuffer class, or Uniform + BufferBlock)
    uint32_t last_array_length = 0; // the block's last member, when it is a sized array
    uint32_t last_array_stride = 0; // its ArrayStride decoration
};

std::map<uint32_t, BufferBlock> buffer_blocks(const std::vector<uint32_t>& spirv) {
    std::map<uint32_t, uint32_t> binding, stride, constant;
    std::set<uint32_t> buffer_block;
    std::map<uint32_t, std::vector<uint32_t>> struct_members;
    std::map<uint32_t, std::pair<uint32_t, uint32_t>> array_of;   // id -> (element, length id)
    std::map<uint32_t, std::pair<uint32_t, uint32_t>> pointer_to; // id -> (storage class, pointee)
    std::vector<std::pair<uint32_t, uint32_t>> variables;         // (pointer type, result id)
    for (size_t i = 5; i < spirv.size();) {
        const uint32_t count = spirv[i] >> 16;
        const spv::Op op = spv::Op(spirv[i] & 0xffff);
        const uint32_t* w = &spirv[i];
        if (count == 0 || i + count > spirv.size()) throw Error("malformed SPIR-V at word " + std::to_string(i));
        if (op == spv::OpDecorate && w[2] == spv::DecorationBinding) binding[w[1]] = w[3];
        if (op == spv::OpDecorate && w[2] == spv::DecorationArrayStride) stride[w[1]] = w[3];
        if (op == spv::OpDecorate && w[2] == spv::DecorationBufferBlock) buffer_block.insert(w[1]);
        if (op == spv::OpTypeStruct) struct_members[w[1]].assign(w + 2, w + count);
        if (op == spv::OpTypeArray) array_of[w[1]] = {w[2], w[3]};
        if (op == spv::OpTypePointer) pointer_to[w[1]] = {w[2], w[3]};
        if (op == spv::OpConstant && count == 4) constant[w[2]] = w[3];
        if (op == spv::OpVariable && (w[3] == spv::StorageClassUniform || w[3] == spv::StorageClassStorageBuffer))
            variables.push_back({w[1], w[2]});
        i += count;
    }
    std::map<uint32_t, BufferBlock> blocks;
    for (auto [type, id] : variables) {
        if (!binding.count(id)) continue;
        auto [storage_class, block] = pointer_to.at(type);
        BufferBlock b;
        b.storage = storage_class == spv::StorageClassStorageBuffer || buffer_block.count(block);
        const std::vector<uint32_t>& members = struct_members.at(block);
        if (!members.empty() && array_of.count(members.back())) {
            b.last_array_length = constant.at(array_of.at(members.back()).second);
            b.last_array_stride = stride.count(members.back()) ? stride.at(members.back()) : 0;
        }
        blocks[binding.at(id)] = b;
    }
    return blocks;
}

std::set<uint32_t> storage_bindings(const std::map<uint32_t, BufferBlock>& blocks) {
    std::set<uint32_t> out;
    for (const auto& [b, block] : blocks)
        if (block.storage) out.insert(b);
    return out;
}

vk::Defines mobile_defaults(const std::string& shading) {
    OptionMap o;
    o.set("shading", shading);
    return glsl_defines(shader_selections(o, "mobile"));
}
} // namespace

TEST(ShadingBuffers, ThePerPixelPassesWriteTheOnlyStorageBuffer) {
    vk::Defines sampled = mobile_defaults("compute");
    sampled.merge(glsl_defines(shader_selections(OptionMap{}, "sampled"))); // mip_clamp
    const auto compute = buffer_blocks(vk::compile_shader("shade_spheres.comp", mobile_defaults("compute")).spirv);
    const auto peer = buffer_blocks(vk::compile_shader("shade_sampled.comp", sampled).spirv);
    for (const auto* blocks : {&compute, &peer}) {
        EXPECT_EQ(storage_bindings(*blocks), std::set<uint32_t>{5}); // the output image
        ASSERT_TRUE(blocks->count(0) && blocks->count(2));           // the scene and the SH coefficients
        EXPECT_FALSE(blocks->at(0).storage);
        EXPECT_FALSE(blocks->at(2).storage);
    }
    // The fragment path writes a colour attachment: no storage buffer in either stage.
    for (const char* stage : {"shade_spheres.vert", "shade_spheres.frag"}) {
        const auto blocks = buffer_blocks(vk::compile_shader(stage, mobile_defaults("fragment")).spirv);
        EXPECT_TRUE(storage_bindings(blocks).empty()) << stage;
    }
}

TEST(ShadingBuffers, TheSceneBlockIsTheSizeTheHostUploads) {
    // scene.glsl's SCENE_SPHERE_CAPACITY and its sphere stride, with and without the AO member,
    // against gpu_scene.h's constants: a mismatch would read spheres at the wrong offsets.
    vk::Defines with_ao = mobile_defaults("compute");
    with_ao["MATERIAL_AO"] = "1";
    for (const auto& [defines, sphere_bytes] :
         {std::pair{mobile_defaults("compute"), kSphereBytes}, std::pair{with_ao, kSphereBytesWithAo}}) {
        const BufferBlock scene = buffer_blocks(vk::compile_shader("shade_spheres.comp", defines).spirv).at(0);
        EXPECT_EQ(scene.last_array_length, kSceneSphereCapacity);
        EXPECT_EQ(scene.last_array_stride, sphere_bytes);
    }
    EXPECT_EQ(kSceneSphereCapacity, 254u); // (16384 − 80) / 64
}

TEST(ShadingBuffers, UploadFillsTheBlockAndRefusesASceneItCannotHold) {
    vk::Context ctx({"", false});
    Scene scene = build_scene("sphere_field", OptionMap{});
    const Sphere first = scene.spheres.front();
    scene.spheres.assign(kSceneSphereCapacity, first);
    vk::Buffer full = upload_scene(ctx, scene);
    ASSERT_EQ(size_t(full.size), scene_buffer_bytes(false));
    uint32_t count = 0;
    std::memcpy(&count, full.as<char>() + 64, 4);
    EXPECT_EQ(count, kSceneSphereCapacity);
    const float* last =
        reinterpret_cast<const float*>(full.as<char>() + kSceneHeaderBytes + (kSceneSphereCapacity - 1) * kSphereBytes);
    EXPECT_EQ(last[3], first.radius);

    // Fewer spheres: the rest of the block is zero (its bytes key the stored instruction counts).
    scene.spheres.resize(3);
    vk::Buffer part = upload_scene(ctx, scene);
    const char* bytes = part.as<char>();
    size_t nonzero = 0;
    for (size_t i = kSceneHeaderBytes + 3 * kSphereBytes; i < scene_buffer_bytes(false); ++i) nonzero += bytes[i] != 0;
    EXPECT_EQ(nonzero, 0u);

    scene.spheres.assign(kSceneSphereCapacity + 1, first);
    try {
        upload_scene(ctx, scene);
        ADD_FAILURE() << "a scene of 255 spheres uploaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'sphere_field' has 255 spheres"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("at most 254"), std::string::npos) << e.what();
    }
}

} // namespace test_shading_buffers
