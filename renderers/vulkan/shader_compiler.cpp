#include "shader_compiler.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string_view>

#include "fp16_emulation.h"
#include "fp16_pass_hash.h" // generated: IBLCHECK_FP16_PASS_HASH
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/hash.h"
#include "kernel/profile.h"
#include "spirv_cost.h"

namespace fs = std::filesystem;

namespace iblcheck::vk {

namespace {

std::string read_text(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    if (!f) throw ShaderCompileError(p.string() + ": cannot open shader source");
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// `ibl_shade`: the team's file that kIblShadeInclude names (CompileOptions::ibl_shade), if any.
fs::path resolve_include(const std::string& name, const fs::path& includer_dir, const fs::path& ibl_shade) {
    if (name == kIblShadeInclude && !ibl_shade.empty()) return fs::weakly_canonical(ibl_shade);
    fs::path a = includer_dir / name;
    if (fs::exists(a)) return fs::weakly_canonical(a);
    fs::path b = shader_dir() / name;
    if (fs::exists(b)) return fs::weakly_canonical(b);
    return {};
}

// The name in a line `#include "NAME"` (spaces allowed around '#' and before the quote), else none.
// By hand: std::regex over every line of every shader was ~3 % of a warm ci run's CPU (issue 33).
std::optional<std::string> quoted_include(std::string_view line) {
    auto skip_space = [&line] {
        while (!line.empty() && std::isspace(static_cast<unsigned char>(line.front()))) line.remove_prefix(1);
    };
    skip_space();
    if (line.empty() || line.front() != '#') return std::nullopt;
    line.remove_prefix(1);
    skip_space();
    if (line.substr(0, 7) != "include") return std::nullopt;
    line.remove_prefix(7);
    skip_space();
    if (line.empty() || line.front() != '"') return std::nullopt;
    line.remove_prefix(1);
    const size_t end = line.find('"');
    if (end == 0 || end == std::string_view::npos) return std::nullopt;
    return std::string(line.substr(0, end));
}

// Hashes the file and, recursively, every file it includes (in order), so the cache key changes
// whenever any of them does. Missing includes are left for glslang to report with file:line.
void hash_sources(const fs::path& file, Fnv1a64& h, std::set<fs::path>& seen, const fs::path& ibl_shade) {
    if (!seen.insert(file).second) return;
    std::string text = read_text(file);
    h.update(file.filename().string());
    h.update(text);
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        if (std::optional<std::string> name = quoted_include(line)) {
            fs::path p = resolve_include(*name, file.parent_path(), ibl_shade);
            if (!p.empty()) hash_sources(p, h, seen, ibl_shade);
        }
    }
}

class FileIncluder : public glslang::TShader::Includer {
  public:
    explicit FileIncluder(fs::path ibl_shade) : ibl_shade_(std::move(ibl_shade)) {}
    IncludeResult* includeLocal(const char* header, const char* includer, size_t) override {
        fs::path dir = fs::path(includer).parent_path();
        fs::path p = resolve_include(header, dir.empty() ? shader_dir() : dir, ibl_shade_);
        if (p.empty()) return nullptr;
        auto* text = new std::string(read_text(p));
        return new IncludeResult(p.string(), text->data(), text->size(), text);
    }
    IncludeResult* includeSystem(const char* header, const char* includer, size_t depth) override {
        return includeLocal(header, includer, depth);
    }
    void releaseInclude(IncludeResult* r) override {
        if (!r) return;
        delete static_cast<std::string*>(r->userData);
        delete r;
    }

  private:
    fs::path ibl_shade_;
};

// glslang reports "ERROR: /path/file.comp:12: 'x' : undeclared identifier"; reformat each to
// "file:line: message" so editors and CI logs link to it.
std::string format_log(const std::string& log) {
    static const std::regex err(R"re((ERROR|WARNING): ([^:\n]+):(\d+): (.*))re");
    std::istringstream in(log);
    std::string line, out;
    while (std::getline(in, line)) {
        std::smatch m;
        if (std::regex_search(line, m, err)) {
            if (m[1] == "WARNING") continue;
            out += m[2].str() + ":" + m[3].str() + ": " + m[4].str() + "\n";
        } else if (line.find("ERROR:") != std::string::npos && line.find("compilation errors") == std::string::npos) {
            out += line + "\n";
        }
    }
    return out.empty() ? log : out;
}

struct GlslangProcess {
    GlslangProcess() { glslang::InitializeProcess(); }
    ~GlslangProcess() { glslang::FinalizeProcess(); }
};

std::mutex& compile_mutex() {
    static std::mutex m;
    return m;
}

} // namespace

fs::path shader_dir() {
    if (const char* env = std::getenv("IBLCHECK_SHADER_DIR"); env && *env) return fs::path(env);
    return fs::path(IBLCHECK_SOURCE_DIR) / "renderers" / "shaders";
}

fs::path spirv_cache_dir() {
    if (const char* env = std::getenv("IBLCHECK_CACHE_DIR"); env && *env) return fs::path(env) / "spirv";
    return fs::path(IBLCHECK_SOURCE_DIR) / ".cache" / "spirv";
}

fs::path spirv_cache_entry(const std::string& source_hash) { return spirv_cache_dir() / (source_hash + ".hashed.spv"); }

std::string shader_tree_hash() {
    std::vector<fs::path> files;
    fs::path dir = shader_dir();
    if (!fs::is_directory(dir)) throw EnvironmentError(dir.string() + ": shader folder not found");
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    Fnv1a64 h;
    for (const auto& f : files) {
        h.update(fs::relative(f, dir).string());
        h.update(read_text(f));
    }
    return h.hex();
}

std::map<std::string, std::string> shader_file_hashes() {
    std::map<std::string, std::string> out;
    const fs::path dir = shader_dir();
    if (!fs::is_directory(dir)) throw EnvironmentError(dir.string() + ": shader folder not found");
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) {
            Fnv1a64 h;
            h.update(read_text(e.path()));
            out[fs::relative(e.path(), dir).generic_string()] = h.hex();
        }
    return out;
}

void check_ibl_shade_file(const fs::path& file) {
    std::error_code ec;
    if (!fs::exists(file, ec))
        throw InputError(file.string() + ": shader file not found (a team's IBL shading, docs/SHADER_CONTRACT.md)");
    if (!fs::is_regular_file(file, ec)) throw InputError(file.string() + ": not a regular file (a GLSL shading file)");
    // The one function the contract asks for; without it glslang would name the harness's file.
    static const std::regex fn(R"re(\bvec3\s+ibl_shade\s*\()re");
    if (!std::regex_search(read_text(file), fn))
        throw InputError(file.string() + ": no function `vec3 ibl_shade(IblSurface s, IblInputs ibl)` (docs/SHADER_CONTRACT.md)");
}

std::string file_tree_hash(const fs::path& file) {
    Fnv1a64 h;
    std::set<fs::path> seen;
    hash_sources(fs::weakly_canonical(file), h, seen, {});
    return h.hex();
}

std::string ibl_shade_hash(const fs::path& file) {
    check_ibl_shade_file(file);
    Fnv1a64 h;
    std::set<fs::path> seen;
    const fs::path canonical = fs::weakly_canonical(file);
    hash_sources(canonical, h, seen, canonical);
    return h.hex();
}

namespace {
struct Stage {
    EShLanguage language;
    const char* key; // part of the cache key; "comp" as before graphics stages existed
};
Stage stage_of(const fs::path& path) {
    std::string ext = path.extension().string();
    if (ext == ".comp") return {EShLangCompute, "comp"};
    if (ext == ".vert") return {EShLangVertex, "vert"};
    if (ext == ".frag") return {EShLangFragment, "frag"};
    throw ShaderCompileError(path.string() + ": unknown shader stage (expected .comp, .vert or .frag)");
}

CompiledShader compile_stage_file(const fs::path& path_in, Stage stage, const Defines& defines, const CompileOptions& options);
} // namespace

CompiledShader compile_compute_shader(const std::string& name, const Defines& defines, const CompileOptions& options) {
    fs::path p = shader_dir() / name;
    if (!fs::exists(p)) throw ShaderCompileError(p.string() + ": shader source not found");
    return compile_compute_shader_file(p, defines, options);
}

CompiledShader compile_compute_shader_file(const fs::path& path_in, const Defines& defines, const CompileOptions& options) {
    return compile_stage_file(path_in, {EShLangCompute, "comp"}, defines, options);
}

CompiledShader compile_shader(const std::string& name, const Defines& defines, const CompileOptions& options) {
    fs::path p = shader_dir() / name;
    if (!fs::exists(p)) throw ShaderCompileError(p.string() + ": shader source not found");
    return compile_shader_file(p, defines, options);
}

CompiledShader compile_shader_file(const fs::path& path, const Defines& defines, const CompileOptions& options) {
    return compile_stage_file(path, stage_of(path), defines, options);
}

namespace {
// The cache key: the stage, the source and every file it includes, the defines, and the passes
// (with their versions) that rewrite the module.
std::string cache_key(const fs::path& path, Stage stage, const Defines& defines, const CompileOptions& options) {
    Fnv1a64 h;
    h.update(std::string(stage.key) + ";glslang-vulkan1.2;");
    std::set<fs::path> seen;
    hash_sources(path, h, seen, options.ibl_shade);
    for (const auto& [k, v] : defines) {
        std::string entry = k;
        h.update(entry.append("=").append(v).append(";"));
    }
    if (options.count_instructions) h.update("count_instructions=" + std::to_string(kCostPassVersion) + ";");
    if (options.emulate_fp16) h.update("pass:fp16-emulation:" IBLCHECK_FP16_PASS_HASH ";");
    return h.hex();
}

std::string preamble_of(const Defines& defines) {
    std::string preamble = "#extension GL_GOOGLE_include_directive : require\n";
    for (const auto& [k, v] : defines) preamble.append("#define ").append(k).append(" ").append(v).append("\n");
    return preamble;
}

// A cache entry is the module's words, then its FNV-1a 64 hash (two words) and this word: an
// entry damaged on disk, even behind an intact SPIR-V header, failed only at pipeline creation
// ("VkResult -13", or worse, a wrong image) and stayed in the cache. The hash costs ~0.1 ms per
// read; spirv-val would cost ~15 ms per module on every run and miss a changed constant.
constexpr uint32_t kCacheTrailer = 0x49424c43u; // "CLBI"
constexpr size_t kTrailerWords = 3;

uint64_t module_hash(const uint32_t* words, size_t count) {
    Fnv1a64 h;
    h.update(words, count * 4);
    return h.value();
}

// The module cached in `file`, if there is a whole one whose hash matches (entries written
// before the hash existed are compiled again, once).
std::optional<std::vector<uint32_t>> read_cached(const fs::path& file) {
    std::ifstream f{file, std::ios::binary};
    if (!f) return std::nullopt;
    std::vector<char> bytes((std::istreambuf_iterator<char>(f)), {});
    if (bytes.size() < 20 + 4 * kTrailerWords || bytes.size() % 4 != 0) return std::nullopt;
    std::vector<uint32_t> words(bytes.size() / 4);
    std::memcpy(words.data(), bytes.data(), bytes.size());
    const size_t n = words.size() - kTrailerWords;
    const uint64_t stored = words[n] | uint64_t(words[n + 1]) << 32;
    if (words[0] != 0x07230203u || words.back() != kCacheTrailer || stored != module_hash(words.data(), n)) return std::nullopt;
    words.resize(n);
    return words;
}

// Write-then-rename so a concurrent reader never sees a half-written file. A cache that cannot be
// written is no error: the next compile does the work again.
void write_cached(const fs::path& file, const std::vector<uint32_t>& spirv) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) return;
    const uint64_t hash = module_hash(spirv.data(), spirv.size());
    const uint32_t trailer[kTrailerWords] = {uint32_t(hash), uint32_t(hash >> 32), kCacheTrailer};
    std::string bytes(reinterpret_cast<const char*>(spirv.data()), spirv.size() * 4);
    bytes.append(reinterpret_cast<const char*>(trailer), sizeof trailer);
    try_write_file_atomically(file, bytes);
}

// GLSL (version 460, Vulkan rules) to SPIR-V 1.5 for Vulkan 1.2, unoptimised. glslang's process
// state is global: one compile at a time.
std::vector<uint32_t> glslang_compile(const fs::path& path, EShLanguage language, const std::string& preamble,
                                      const fs::path& ibl_shade) {
    std::string source = read_text(path);
    std::lock_guard lock(compile_mutex());
    static GlslangProcess process;
    glslang::TShader shader(language);
    const char* src = source.c_str();
    std::string name = path.string();
    const char* names = name.c_str();
    shader.setStringsWithLengthsAndNames(&src, nullptr, &names, 1);
    shader.setPreamble(preamble.c_str());
    shader.setEntryPoint("main");
    shader.setEnvInput(glslang::EShSourceGlsl, language, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
    FileIncluder includer(ibl_shade);
    auto msgs = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    if (!shader.parse(GetDefaultResources(), 460, false, msgs, includer))
        throw ShaderCompileError(format_log(shader.getInfoLog()));
    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(msgs)) throw ShaderCompileError(name + ": link: " + format_log(program.getInfoLog()));
    glslang::SpvOptions opt;
    opt.disableOptimizer = true; // lavapipe's LLVM optimises; keep SPIR-V faithful to the source
    std::vector<uint32_t> spirv;
    glslang::GlslangToSpv(*program.getIntermediate(language), spirv, &opt);
    return spirv;
}

// The SPIR-V passes `options` asks for, in their one valid order.
void apply_passes(std::vector<uint32_t>& spirv, const CompileOptions& options, const fs::path& path) {
    // The count comes before the fp16 emulation: it measures the shader as written (what a device
    // with native fp16 executes), so the cost a baseline records is the same on every CPU class.
    // The emulation only rewrites 16-bit float instructions and adds no blocks, so the counter's
    // per-block increments (64-bit integers) pass through it unchanged.
    if (options.count_instructions) spirv = instrument_instruction_count(spirv);
    if (options.emulate_fp16) {
        try {
            emulate_fp16(spirv);
        } catch (const ShaderCompileError& e) {
            throw ShaderCompileError(path.string() + ": " + e.what());
        }
    }
}

CompiledShader compile_stage_file(const fs::path& path_in, Stage stage, const Defines& defines, const CompileOptions& options) {
    ProfileStage profile_stage("spirv_compile_or_cache");
    const fs::path path = fs::weakly_canonical(path_in);
    if (!options.ibl_shade.empty()) check_ibl_shade_file(options.ibl_shade); // before its text is hashed
    CompiledShader out;
    out.source_hash = cache_key(path, stage, defines, options);
    out.counts_instructions = options.count_instructions;
    const fs::path cached = spirv_cache_entry(out.source_hash);
    if (auto spirv = read_cached(cached)) {
        out.spirv = std::move(*spirv);
        out.from_cache = true;
        return out;
    }
    out.spirv = glslang_compile(path, stage.language, preamble_of(defines), options.ibl_shade);
    apply_passes(out.spirv, options, path);
    write_cached(cached, out.spirv);
    return out;
}

} // namespace

} // namespace iblcheck::vk
