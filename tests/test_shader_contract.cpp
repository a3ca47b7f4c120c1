// Issue 29, "Your shader": a team's IBL shading through the shader contract (docs/SHADER_CONTRACT.md).
// The suite field and its test names, the cache key and provenance hash that follow the file and
// its includes, the texture-sample count of the cost gate, the errors (exit 2 naming the file),
// and the example (examples/filament_ibl) failing the ci suite when a bug or three more lookups
// are put into a copy.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/bless.h"
#include "harness/suite.h"
#include "kernel/errors.h"
#include "renderers/vulkan/shader_compiler.h"
#include "renderers/vulkan/spirv_texture_samples.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_shader_contract {

namespace {

const fs::path kExample = fs::path(IBLCHECK_SOURCE_DIR) / "examples/filament_ibl/filament_ibl.glsl";

const char* kShade = "vec3 ibl_shade(IblSurface s, IblInputs ibl) { return s.base_color; }\n";

// A suite in `dir` whose mobile tests run `shader` (relative to the suite).
fs::path write_suite(const fs::path& dir, const std::string& shader_entry) {
    write_file(dir / "s.json", R"({"suite": "s", "defaults": {"env": "constant:1",
      "baseline_tolerances": {"flip.mean": {"max": 0.001}}},
      "tests": [)" + shader_entry + R"(]})");
    return dir / "s.json";
}

// The error message of loading `suite`, or "" when it loads.
std::string load_error(const fs::path& suite) {
    try {
        load_suite(suite.string());
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(ShaderContract, SuiteShaderIsRelativeToTheSuiteFileAndNamesItsTests) {
    const fs::path dir = temp_dir("contract_suite");
    write_file(dir / "team/my_ibl.glsl", kShade);
    const fs::path suite = write_suite(dir, R"({"scene": "furnace", "method": "mobile", "shader": "team/my_ibl.glsl",
                                               "variants": [{}, {"mip_mapping": "filament"}]},
                                              {"scene": "furnace", "method": "mobile"})");
    const Suite s = load_suite(suite.string());
    ASSERT_EQ(s.tests.size(), 3u);
    EXPECT_EQ(s.tests[0].name, "mobile.furnace.constant:1.shader=my_ibl");
    EXPECT_EQ(s.tests[1].name, "mobile.furnace.constant:1.shader=my_ibl,mip_mapping=filament");
    EXPECT_EQ(s.tests[0].spec.shader, (dir / "team/my_ibl.glsl").string());
    EXPECT_EQ(s.tests[2].name, "mobile.furnace.constant:1.default"); // the built-in keeps its name and baseline
    EXPECT_TRUE(s.tests[2].spec.shader.empty());

    // --shader: every mobile test runs it (the suite's own shader too), and its bless command repeats it.
    const fs::path other = write_suite(dir, R"({"scene": "furnace", "method": "mobile", "shader": "team/my_ibl.glsl"},
                                               {"scene": "sphere", "method": "mobile"},
                                               {"scene": "sphere", "method": "sampled"})");
    write_file(dir / "cli/team_b.glsl", kShade);
    const Suite all = load_suite(other.string(), (dir / "cli/team_b.glsl").string());
    ASSERT_EQ(all.tests.size(), 3u);
    EXPECT_EQ(all.tests[0].name, "mobile.furnace.constant:1.shader=team_b");
    EXPECT_EQ(all.tests[1].name, "mobile.sphere.constant:1.shader=team_b");
    EXPECT_EQ(all.tests[1].shader_arg, (dir / "cli/team_b.glsl").string());
    EXPECT_EQ(all.tests[2].name, "sampled.sphere.constant:1.default"); // only the mobile method runs it
    EXPECT_NE(bless_command(all.tests[1]).find(" --shader '" + (dir / "cli/team_b.glsl").string() + "' --filter "),
              std::string::npos)
        << bless_command(all.tests[1]);
}

TEST(ShaderContract, SuiteRefusesAMissingShaderOneWithoutIblShadeAndABuiltInOption) {
    const fs::path dir = temp_dir("contract_suite_errors");
    std::string e = load_error(write_suite(dir, R"({"scene": "furnace", "method": "mobile", "shader": "nope.glsl"})"));
    EXPECT_NE(e.find("tests[0].shader"), std::string::npos) << e;
    EXPECT_NE(e.find((dir / "nope.glsl").string() + ": shader file not found"), std::string::npos) << e;

    write_file(dir / "other.glsl", "vec3 shade(vec3 n) { return n; }\n");
    e = load_error(write_suite(dir, R"({"scene": "furnace", "method": "mobile", "shader": "other.glsl"})"));
    EXPECT_NE(e.find((dir / "other.glsl").string() + ": no function `vec3 ibl_shade("), std::string::npos) << e;

    write_file(dir / "ok.glsl", kShade);
    e = load_error(write_suite(dir, R"({"scene": "furnace", "method": "mobile", "shader": "ok.glsl",
                                        "options": {"dominant_dir": "lagarde"}})"));
    EXPECT_NE(e.find("option 'dominant_dir' selects part of the built-in shading"), std::string::npos) << e;
    e = load_error(write_suite(dir, R"({"scene": "furnace", "method": "sampled", "shader": "ok.glsl"})"));
    EXPECT_NE(e.find("runs in the mobile method only"), std::string::npos) << e;
}

TEST(ShaderContract, CacheKeyAndProvenanceHashFollowTheFileAndItsIncludes) {
    const fs::path dir = temp_dir("contract_cache");
    setenv("IBLCHECK_CACHE_DIR", dir.c_str(), 1);
    write_file(dir / "pass.comp", "#version 460\nlayout(local_size_x = 1) in;\nstruct IblSurface { vec3 c; };\n"
                                  "struct IblInputs { float x; };\n#include \"ibl_shade_user.glsl\"\nvoid main() {}\n");
    write_file(dir / "team/helper.glsl", "const float K = 1.0;\n");
    write_file(dir / "team/ibl.glsl",
               "#include \"helper.glsl\"\nvec3 ibl_shade(IblSurface s, IblInputs ibl) { return s.c * K; }\n");
    vk::CompileOptions o;
    o.ibl_shade = dir / "team/ibl.glsl";
    const std::string key = vk::compile_shader_file(dir / "pass.comp", {}, o).source_hash;
    const std::string hash = vk::ibl_shade_hash(o.ibl_shade);
    write_file(dir / "team/helper.glsl", "const float K = 2.0;\n"); // an include of the team's file
    const vk::CompiledShader again = vk::compile_shader_file(dir / "pass.comp", {}, o);
    EXPECT_NE(again.source_hash, key);
    EXPECT_FALSE(again.from_cache); // compiled again, not the old SPIR-V
    EXPECT_NE(vk::ibl_shade_hash(o.ibl_shade), hash);
    unsetenv("IBLCHECK_CACHE_DIR");
}

TEST(ShaderContract, TextureSamplesCountEveryCallSiteOfIblShade) {
    const fs::path dir = temp_dir("contract_samples");
    setenv("IBLCHECK_CACHE_DIR", dir.c_str(), 1);
    write_file(dir / "pass.comp", "#version 460\nlayout(local_size_x = 1) in;\nlayout(binding = 0) uniform sampler2D t;\n"
                                  "layout(binding = 1) buffer O { vec4 o; };\n"
                                  "vec4 fetch(vec2 uv) { return textureLod(t, uv, 0.0); }\n"
                                  "vec4 ibl_shade(vec2 uv) { return fetch(uv) + fetch(uv * 2.0) + texture(t, uv); }\n"
                                  "vec4 other() { return textureLod(t, vec2(0.5), 1.0); }\n"
                                  "void main() { o = ibl_shade(vec2(0.25)) + other(); }\n");
    const vk::CompiledShader m = vk::compile_shader_file(dir / "pass.comp");
    EXPECT_EQ(vk::image_samples_per_call(m.spirv, "ibl_shade("), 3.0); // two calls of fetch + one; other() not
    EXPECT_THROW(vk::image_samples_per_call(m.spirv, "missing("), Error);
    unsetenv("IBLCHECK_CACHE_DIR");
}

TEST(Cli, ContractShaderErrorsAreExit2NamingTheFile) {
    const fs::path dir = temp_dir("contract_cli_errors");
    const std::string render = "IBLCHECK_CACHE_DIR=" + dir.string() + " " + built("iblcheck") +
                               " render --scene furnace --env constant:1 --set cube_size=16 --shader ";
    std::string out;
    EXPECT_EQ(run_command(render + (dir / "missing.glsl").string(), out), 2) << out;
    EXPECT_NE(out.find((dir / "missing.glsl").string() + ": shader file not found"), std::string::npos) << out;

    write_file(dir / "nofn.glsl", "vec3 shade_it(vec3 n) { return n; }\n");
    EXPECT_EQ(run_command(render + (dir / "nofn.glsl").string(), out), 2) << out;
    EXPECT_NE(out.find((dir / "nofn.glsl").string() + ": no function `vec3 ibl_shade("), std::string::npos) << out;

    write_file(dir / "bad.glsl", "// line 1\nvec3 ibl_shade(IblSurface s, IblInputs ibl) { return not_declared; }\n");
    EXPECT_EQ(run_command(render + (dir / "bad.glsl").string(), out), 2) << out;
    EXPECT_NE(out.find(fs::canonical(dir / "bad.glsl").string() + ":2: 'not_declared' : undeclared identifier"),
              std::string::npos)
        << out;
}

// The done-when of issue 29: the example passes ci with its own baselines (the suite.ci CTest tests
// mobile.*.shader=filament_ibl*), and a deliberate bug in it fails ci. The ci suite's entries that
// run the example, with the shader pointed at a copy: the copy keeps the file name, so the tests
// keep their names and are judged against the example's committed baselines.
TEST(Cli, ContractShaderBugFailsTheRun) {
    const fs::path dir = temp_dir("contract_bug");
    nlohmann::json ci = nlohmann::json::parse(read_text(fs::path(IBLCHECK_SOURCE_DIR) / "harness/suites/ci.json"));
    nlohmann::json tests = nlohmann::json::array();
    for (const auto& t : ci["tests"])
        if (t.contains("shader")) tests.push_back(t);
    ASSERT_EQ(tests.size(), 2u) << "the ci suite runs the example in two tests";
    auto suite_for = [&](const std::string& folder, const std::string& text) {
        write_file(dir / folder / "filament_ibl.glsl", text);
        nlohmann::json s = ci;
        s["tests"] = tests;
        for (auto& t : s["tests"]) t["shader"] = (dir / folder / "filament_ibl.glsl").string();
        write_file(dir / folder / "ci_example.json", s.dump());
        return "IBLCHECK_CACHE_DIR=" + dir.string() + " " + built("iblcheck") + " run --suite " +
               (dir / folder / "ci_example.json").string();
    };
    std::string text = read_text(kExample), out;
    EXPECT_EQ(run_command(suite_for("same", text), out), 0) << out; // the copy itself passes

    const std::string from = "1.0 + f0 * (1.0 / max(dfg.y, 1e-4) - 1.0)"; // the energy compensation, sign flipped
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), "1.0 - f0 * (1.0 / max(dfg.y, 1e-4) - 1.0)");
    EXPECT_EQ(run_command(suite_for("bug", text), out), 1) << out;
    EXPECT_NE(out.find("mobile.roughness_sweep.studio.shader=filament_ibl"), std::string::npos) << out;
    EXPECT_NE(out.find("baseline: flip.mean"), std::string::npos) << out;

    // The cost gate on a team's shading: the same pixels from four lookups instead of one.
    text = read_text(kExample);
    const std::string lookup = "    vec3 radiance = ibl_prefiltered(dir, fil_lod(ibl, r));\n";
    ASSERT_NE(text.find(lookup), std::string::npos);
    text.insert(text.find(lookup) + lookup.size(),
                "    radiance = 0.25 * (radiance + ibl_prefiltered(dir, fil_lod(ibl, r)) + "
                "ibl_prefiltered(dir, fil_lod(ibl, r)) + ibl_prefiltered(dir, fil_lod(ibl, r)));\n");
    EXPECT_EQ(run_command(suite_for("cost", text), out), 1) << out;
    EXPECT_NE(out.find("cost: cost.texture_fetches_per_pixel"), std::string::npos) << out;
    EXPECT_NE(out.find("+150.0 %"), std::string::npos) << out; // 2 fetches a shading (cube + LUT) -> 5
}
} // namespace test_shader_contract
