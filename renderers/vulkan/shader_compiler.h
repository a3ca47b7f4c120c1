// Run-time GLSL → SPIR-V compilation with glslang, so a shader edit needs no rebuild.
//
// Sources live under renderers/shaders/ (IBLCHECK_SHADER_DIR overrides the folder, which is how
// `iblcheck bisect` and the gate test point at a modified copy). `#include "x.glsl"` resolves
// relative to the including file, then to the shader folder. Variants are preprocessor defines
// (named as the options are: DOMINANT_DIR, MIP_MAPPING, ...) or specialization constants set at
// pipeline creation. Compiled SPIR-V is cached on disk, keyed by a hash of the source text of
// the file and everything it includes, plus the defines, the stage and the CompileOptions.
// Each entry carries a hash of its words: a damaged entry is compiled again and rewritten.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace iblcheck::vk {

using Defines = std::map<std::string, std::string>;

// What is done to the SPIR-V after glslang (each part of the cache key).
struct CompileOptions {
    // Run the fp16 emulation pass (fp16_emulation.h): float16_t arithmetic on a driver without
    // shaderFloat16. A no-op on modules without 16-bit floats.
    bool emulate_fp16 = false;
    // Instrument the SPIR-V to count the instructions each invocation executes (spirv_cost.h).
    // Applied last, so it counts exactly what the pipeline runs.
    bool count_instructions = false;
    // A team's IBL shading (docs/SHADER_CONTRACT.md): the file `#include "ibl_shade_user.glsl"`
    // resolves to (empty: the built-in shading). Its text and its includes are in the cache key.
    std::filesystem::path ibl_shade;
};

struct CompiledShader {
    std::vector<uint32_t> spirv;
    std::string source_hash; // hash of the sources + defines + options: the key of the cache, for provenance
    bool from_cache = false;
    bool counts_instructions = false; // instrumented by spirv_cost.h: binds the counter at kCostBinding
};

// The folder shaders are read from: $IBLCHECK_SHADER_DIR or <source root>/renderers/shaders.
std::filesystem::path shader_dir();

// Compiles the compute shader `name` (a file under shader_dir(), e.g. "prefilter_ggx.comp").
// Throws ShaderCompileError whose message starts "file:line: " for every error glslang reports.
CompiledShader compile_compute_shader(const std::string& name, const Defines& defines = {}, const CompileOptions& options = {});

// Same, for a full path (tests compile shaders from temporary folders).
CompiledShader compile_compute_shader_file(const std::filesystem::path& path, const Defines& defines = {},
                                           const CompileOptions& options = {});

// Any stage, named by the file's extension: .comp, .vert or .frag (graphics_pipeline.h).
// ShaderCompileError for another extension.
CompiledShader compile_shader(const std::string& name, const Defines& defines = {}, const CompileOptions& options = {});
CompiledShader compile_shader_file(const std::filesystem::path& path, const Defines& defines = {},
                                   const CompileOptions& options = {});

// A hash over every .glsl/.comp file in shader_dir(): the "shader source hash" of provenance.
std::string shader_tree_hash();
// The content hash of each file of the shader folder, by its path relative to it: a sidecar keeps
// them so the report can say which files changed since a baseline was blessed (issue 32).
std::map<std::string, std::string> shader_file_hashes();

// The include name a pass uses for the team's shading file (CompileOptions::ibl_shade).
inline constexpr const char* kIblShadeInclude = "ibl_shade_user.glsl";
// A team's shading file checked before any compile: it exists, is a regular file and defines
// `vec3 ibl_shade(` (docs/SHADER_CONTRACT.md). Throws InputError naming the file (exit 2).
void check_ibl_shade_file(const std::filesystem::path& file);
// A hash of a team's shading file and, recursively, every file it includes: its provenance.
std::string ibl_shade_hash(const std::filesystem::path& file);
// The same over a harness shader (a pass under shader_dir()): its text and every file it includes.
std::string file_tree_hash(const std::filesystem::path& file);

// Where cached SPIR-V goes: $IBLCHECK_CACHE_DIR/spirv or <source root>/.cache/spirv.
std::filesystem::path spirv_cache_dir();
// The cache entry of a CompiledShader's source_hash: <key>.hashed.spv, the module followed by its
// hash. Not <key>.spv, which commits before the hash read as a whole module (a bisect builds them
// in the same checkout, sharing the cache).
std::filesystem::path spirv_cache_entry(const std::string& source_hash);

} // namespace iblcheck::vk
