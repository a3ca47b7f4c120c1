// The option table (renderers/option_table.h) drives `list`, validation, the host's reading of
// enumerations and the shaders' defines. These tests hold the table and the GLSL together: every
// value of a shader option has code, a shader never falls back to a default of its own, and every
// value compiles.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "kernel/errors.h"
#include "renderers/option_table.h"
#include "renderers/renderer.h"
#include "renderers/vulkan/shader_compiler.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_option_table {

namespace {
std::string shader_sources() {
    std::string all;
    for (const auto& entry : fs::directory_iterator(fs::path(IBLCHECK_SOURCE_DIR) / "renderers/shaders")) {
        std::ifstream in(entry.path());
        std::stringstream ss;
        ss << in.rdbuf();
        all += ss.str();
    }
    return all;
}
} // namespace

TEST(OptionTable, EnumerationsListTheirDefaultFirst) {
    int enumerations = 0;
    for (const auto& o : option_catalog()) {
        if (!o.enumerated()) continue;
        ++enumerations;
        ASSERT_FALSE(o.choices().empty()) << o.key;
        EXPECT_EQ(o.choices().front(), option_value_text(o.defaults.value)) << o.key;
    }
    EXPECT_GE(enumerations, 9);
}

TEST(OptionTable, KeysAreUnique) {
    std::set<std::string> keys;
    for (const auto& o : option_catalog()) EXPECT_TRUE(keys.insert(o.key).second) << o.key;
}

TEST(OptionTable, MethodsAreMatchedWhole) {
    EXPECT_TRUE(option_info("seed").read_by("reference"));
    EXPECT_TRUE(option_info("seed").read_by("sampled"));
    EXPECT_FALSE(option_info("seed").read_by("mobile"));
    EXPECT_FALSE(option_info("seed").read_by("sample"));
    EXPECT_TRUE(option_info("roughness").read_by("anything"));
}

TEST(OptionTable, GlslNamesAndIndices) {
    EXPECT_EQ(glsl_value_name(option_info("diffuse"), "irradiance_cube"), "DIFFUSE_IRRADIANCE_CUBE");
    auto d = glsl_defines({{"mip_mapping", "origin"}});
    EXPECT_EQ(d.at("MIP_MAPPING"), "2");
    EXPECT_EQ(d.at("MIP_MAPPING_UE4"), "0");
    EXPECT_EQ(d.at("MIP_MAPPING_ORIGIN"), "2");
    EXPECT_EQ(d.at("STORAGE_R11G11B10"), "3"); // named values of every shader option are always there
    EXPECT_EQ(d.count("STORAGE"), 0u);         // but only the selected options get a selection
    EXPECT_EQ(glsl_selection_names({{"storage", "rgbm8"}}).at("STORAGE"), "STORAGE_RGBM8");
}

TEST(OptionTable, UnknownValueNamesKeyAndValidValues) {
    try {
        glsl_defines({{"specular_aa", "tokuyosi"}});
        FAIL() << "no error";
    } catch (const UsageError& e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("'specular_aa'"), std::string::npos) << msg;
        EXPECT_NE(msg.find("tokuyosi"), std::string::npos) << msg;
        EXPECT_NE(msg.find("toksvig"), std::string::npos) << msg;
    }
    OptionMap o;
    o.set("mip_mapping", "orgin");
    TestSpec spec;
    spec.method = "mobile";
    spec.scene = "sphere";
    spec.env = "constant:1";
    spec.options = o;
    EXPECT_THROW(validate_spec(spec), UsageError);
}

TEST(OptionTable, SelectionsComeFromTheTable) {
    OptionMap o;
    o.set("specular_aa", "rjump");
    auto s = shader_selections(o, "mobile");
    EXPECT_EQ(s.at("specular_aa"), "rjump");
    EXPECT_EQ(s.at("storage"), option_value_text(option_info("storage").defaults.value));
    for (const auto& info : option_catalog()) {
        if (!info.glsl_define.empty() && info.read_by("mobile")) {
            EXPECT_EQ(s.count(info.key), 1u) << info.key;
        }
    }
    // The sampled peer's one shader option: seed 002's mip clamp (issue 27).
    EXPECT_EQ(shader_selections(o, "sampled"), (std::map<std::string, std::string>{{"mip_clamp", "roughness"}}));
}

TEST(OptionTable, EveryNonDefaultShaderValueHasShaderCode) {
    // The default may be a shader's #else; every other value must be named in GLSL, or selecting
    // it would silently run another variant's code.
    std::string glsl = shader_sources();
    for (const auto& info : option_catalog()) {
        if (info.glsl_define.empty()) continue;
        auto choices = info.choices();
        for (size_t i = 1; i < choices.size(); ++i) {
            std::string name = glsl_value_name(info, choices[i]);
            EXPECT_NE(glsl.find(info.glsl_define + " == " + name), std::string::npos)
                << info.key << "=" << choices[i] << ": no `" << info.glsl_define << " == " << name << "` in the shaders";
        }
    }
}

TEST(OptionTable, AShaderWithoutItsDefineDoesNotCompile) {
    auto defs = glsl_defines(shader_selections(OptionMap{}, "mobile"));
    EXPECT_NO_THROW(vk::compile_compute_shader("shade_spheres.comp", defs));
    for (const char* define : {"STORAGE", "SPECULAR_AA", "PRECISION", "SHADING"}) {
        auto missing = defs;
        missing.erase(define);
        try {
            vk::compile_compute_shader("shade_spheres.comp", missing);
            ADD_FAILURE() << define << ": compiled without its define";
        } catch (const ShaderCompileError& e) {
            EXPECT_NE(std::string(e.what()).find(std::string(define) + " is set from the option table"), std::string::npos)
                << e.what();
        }
    }
}

TEST(OptionTable, EveryValueOfEveryShaderOptionCompiles) {
    // In both shading paths: shade_spheres.comp, or shade_spheres.vert + .frag (issue 18).
    for (std::string shading : option_info("shading").choices())
        for (const auto& info : option_catalog()) {
            if (info.glsl_define.empty() || !info.read_by("mobile")) continue;
            for (const auto& value : info.choices()) {
                OptionMap o;
                o.set("shading", shading);
                o.set(info.key, value);
                auto defs = glsl_defines(shader_selections(o, "mobile"));
                std::string what = info.key + "=" + value + " shading=" + option_choice(o, "shading");
                if (option_choice(o, "shading") == "fragment") {
                    EXPECT_NO_THROW(vk::compile_shader("shade_spheres.vert", defs)) << what;
                    EXPECT_NO_THROW(vk::compile_shader("shade_spheres.frag", defs)) << what;
                } else {
                    EXPECT_NO_THROW(vk::compile_compute_shader("shade_spheres.comp", defs)) << what;
                }
            }
        }
}

TEST(OptionTable, EachShadingPathRefusesTheOthersDefine) {
    // The host picks the pass from the same table value the shaders test: a mismatch is a compile
    // error naming the option table, never the other path's code running silently.
    OptionMap fragment;
    fragment.set("shading", "fragment");
    auto frag_defs = glsl_defines(shader_selections(fragment, "mobile"));
    auto comp_defs = glsl_defines(shader_selections(OptionMap{}, "mobile"));
    EXPECT_THROW(vk::compile_compute_shader("shade_spheres.comp", frag_defs), ShaderCompileError);
    EXPECT_THROW(vk::compile_shader("shade_spheres.frag", comp_defs), ShaderCompileError);
    EXPECT_THROW(vk::compile_shader("shade_spheres.vert", comp_defs), ShaderCompileError);
}
} // namespace test_option_table
