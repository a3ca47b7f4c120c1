#include "option_table.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include <fmt/format.h>

#include "kernel/errors.h"

namespace iblcheck {

const std::vector<OptionInfo>& option_catalog() {
    // key, default (typed; {value, {{where, value}, ...}} where it differs), values, methods, GLSL define, description
    static const std::vector<OptionInfo> table = {
        {"roughness",
         {0.5, {{"bumpy_sphere", 0.05}, {"sphere_field", 0.05}}},
         "0..1",
         "all",
         "",
         "perceptual roughness of the one-sphere scenes (alpha = r^2)"},
        {"metallic",
         {0.0, {{"bumpy_sphere", 1.0}, {"sphere_field", 1.0}}},
         "0..1",
         "all",
         "",
         "metalness of the one-sphere scenes"},
        {"base_color",
         {Vec3f{1, 1, 1}, {{"bumpy_sphere", Vec3f{0.95f, 0.93f, 0.88f}}, {"sphere_field", Vec3f{0.95f, 0.93f, 0.88f}}}},
         "r,g,b",
         "all",
         "",
         "base colour of the one-sphere scenes"},
        {"env_rotation", {0.0}, "degrees", "all", "", "turns the environment about +Y"},
        {"frame", {0}, "integer", "all", "", "frame of an animated scene (bumpy_sphere)"},
        {"bump_amplitude", {0.0008}, ">=0", "all", "", "height of the bumpy_sphere normal detail"},
        {"roughness_bias", {0.0}, "-1..1", "all", "", "stability: added to every sphere's roughness"},
        {"camera_shift", {Vec3f{0, 0, 0}}, "pixels x,y,0", "all", "", "stability: moves the camera by a fraction of a pixel"},
        {"bump_frequency", {200.0}, ">0", "all", "", "spatial frequency of the bumpy_sphere normal detail (radius-1 units)"},
        {"ao",
         {1.0},
         "0..1",
         "mobile",
         "",
         "material ambient occlusion of every sphere: multiplies its diffuse lighting and indirect_irradiance (UE4; so, under a "
         "normalisation, its reflections)"},
        {"ssaa",
         {2, {{"shading=fragment", 1}}},
         "1..16",
         "mobile,sampled",
         "",
         "n x n rays per pixel (silhouettes); shading=fragment: renders n x n times the pixels and averages them"},
        {"cube_size", {128, {{"sampled", 256}}}, "8..2048, power of two", "mobile,sampled", "", "base size of the cubemaps"},
        {"mips",
         {{}, {}, "the full chain"},
         "2..log2(cube_size)+1",
         "mobile",
         "",
         "levels of the prefiltered chain; by default all the layout holds (cube: down to 1x1); a count whose last level is "
         "below r = 1 (UE4's curve reaches it at mip log2(cube_size)-2) is refused"},
        {"prefilter_samples",
         {256},
         "1..65536",
         "mobile",
         "",
         "GGX samples per prefiltered texel (filtered importance sampling); against a 4096-sample bake, the noise is under 1 % "
         "of the default's error against the truth in studio, sunrise and interior and 3 % in sky_sun (64: up to 6 %)"},
        {"shading",
         {"compute"},
         "compute|fragment",
         "mobile",
         "SHADING",
         "compute: each pixel ray-traces the spheres, specular AA from neighbouring rays; fragment: sphere impostors "
         "in a graphics pipeline, MSAA 4x, specular AA from the hardware quads' dFdx/dFdy"},
        {"mip_mapping", {"ue4"}, "ue4|filament|origin", "mobile", "MIP_MAPPING", "roughness <-> mip mapping"},
        {"env_brdf", {"approx"}, "approx|lut", "mobile", "ENV_BRDF", "EnvBRDFApprox (Karis/Lazarov) or a DFG LUT pass"},
        {"lut_size", {64}, "8..512", "mobile", "", "DFG LUT resolution (env_brdf=lut)"},
        {"diffuse", {"sh9"}, "sh9|irradiance_cube", "mobile", "DIFFUSE", "diffuse irradiance representation"},
        {"dominant_dir", {"off"}, "off|lagarde|filament", "mobile", "DOMINANT_DIR", "specular dominant direction"},
        {"lagarde_roughness",
         {"alpha"},
         "alpha|perceptual",
         "mobile",
         "LAGARDE_ROUGHNESS",
         "dominant_dir=lagarde: the roughness its formula is fed: alpha = r^2 (Frostbite's listing 22/24, as EEVEE) or the "
         "perceptual r (as some ports)"},
        {"normalization",
         {"off"},
         "off|ue4|directional",
         "mobile",
         "NORMALIZATION",
         "UE4 mobile reflection normalisation (MixingAlpha); directional: the ratio at n (SH9 E(n) / the prefiltered chain's at "
         "n) instead of UE4's scalar one"},
        {"mix_begin_roughness", {0.1}, "0..1", "mobile", "", "normalisation: roughness where mixing starts"},
        {"mix_end_roughness", {0.3}, "0..1", "mobile", "", "normalisation: roughness where mixing is full"},
        {"mix_largest_weight", {10000.0}, ">0", "mobile", "", "normalisation: clamp of the mixing weight"},
        {"indirect_irradiance", {"sh9"}, "sh9 or a number", "mobile", "", "normalisation: lightmap/ILC brightness"},
        {"storage",
         {"rgba16f"},
         "rgba16f|rgba32f|rgbm8|r11g11b10|astc_hdr|astc_ldr_rgbm",
         "mobile",
         "STORAGE",
         "prefiltered cube storage; astc_*: encoded and decoded on the CPU by astcenc (libastcenc-dev), see astc_block"},
        {"astc_block",
         {"4x4"},
         "4x4|6x6",
         "mobile",
         "",
         "ASTC block footprint (storage=astc_*): 4x4 = 8 bits per texel, 6x6 = 3.56"},
        {"rgbm_range",
         {"peak"},
         "peak or >0",
         "mobile",
         "",
         "RGBM range (storage=rgbm8, astc_ldr_rgbm); peak: the base cube's largest value, as UE4.26 derives a mobile capture's "
         "MaxValueRGBM; the results give the range and the energy it clips"},
        {"env_layout",
         {"cube"},
         "cube|octahedral|equirect",
         "mobile",
         "ENV_LAYOUT",
         "layout of the prefiltered radiance: a cubemap (NxN x6) or one 2D texture, octahedral (2Nx2N) or lat-long (4Nx2N), with "
         "a 1-texel border per level"},
        {"precision", {"highp"}, "highp|mediump", "mobile", "PRECISION", "mediump shades in float16_t"},
        {"fp16",
         {"auto"},
         "auto|native|emulated",
         "mobile",
         "",
         "precision=mediump: native float16_t, or emulated (fp32 rounded to fp16 per operation); auto: native if shaderFloat16"},
        {"specular_aa",
         {"off"},
         "off|tokuyoshi|rjump|toksvig",
         "mobile",
         "SPECULAR_AA",
         "specular anti-aliasing for low roughness"},
        {"specular_aa_variance", {0.25}, ">=0", "mobile", "", "specular AA: screen-space variance scale"},
        {"specular_aa_threshold", {0.18}, ">=0", "mobile", "", "specular AA: clamp of the added roughness"},
        {"samples", {64}, "1..65536", "sampled", "", "GGX samples per ray"},
        {"min_lod", {0.0}, ">=0", "sampled", "", "lowest mip a sample may read"},
        {"mip_clamp",
         {"roughness"},
         "roughness|off",
         "sampled",
         "MIP_CLAMP",
         "roughness: no sample reads a level finer than a quarter of the GGX lobe, 2^lod >= alpha*cube_size/pi (seed 002's clamp "
         "of "
         "the lowest mip by roughness); off: only min_lod"},
        {"diffuse_roughness", {0.9}, "0..1", "sampled", "", "roughness from which radiance blends to irradiance"},
        {"seed", {0}, "integer", "sampled,reference", "", "random seed"},
        {"spp", {256}, ">=1", "reference", "", "samples per pixel (selects the Monte Carlo integrator)"},
        {"integrator",
         {"quadrature", {{"spp set", "monte_carlo"}}},
         "quadrature|monte_carlo",
         "reference",
         "",
         "quadrature truth (default; monte_carlo when spp is set)"},
        {"truth_tolerance", {0.001}, ">0", "reference", "", "quadrature truth: the coarser level's per-pixel tolerance"},
        {"threads", {0}, ">=0", "reference", "", "CPU threads (0: all)"},
        {"split_sum",
         {"off"},
         "off|exact|env_brdf_approx",
         "reference",
         "",
         "quadrature truth: off renders the truth; exact / env_brdf_approx the split sum's rungs of `iblcheck explain` "
         "(prefiltered radiance at n = v = R times the exact DFG or EnvBRDFApprox, plus the exact diffuse; the coarse level "
         "only; renderers/reference/quadrature/split_sum.h)"},
        // The Monte Carlo integrator's knobs (monte_carlo.h, "Options"): set by the tests and the truth tools, not by --set.
        {"pixel_pattern", {0}, "integer", "reference", "", "Monte Carlo: the key of the sub-pixel positions' pattern", true},
        {"positions", {{}, {}, "spp/4"}, "1..spp", "reference", "", "Monte Carlo: sub-pixel positions per pixel", true},
        {"adaptive", {1}, "0 or 1", "reference", "", "Monte Carlo: adaptive lighting counts from a pilot pass", true},
        {"adaptive_cap", {16}, ">=1", "reference", "", "Monte Carlo: the adaptive counts' cap, times the mean", true},
        {"silhouette_boost", {16}, ">=1", "reference", "", "Monte Carlo: silhouette pixels' least count, times the mean", true},
        {"lobes", {"all"}, "all|diffuse|specular", "reference", "", "both integrators: evaluate only that lobe (tests)", true},
        {"mis", {"power"}, "power|balance", "reference", "", "Monte Carlo: the MIS heuristic", true},
        {"env_sampling", {"window"}, "window|global", "reference", "", "Monte Carlo: the environment's sampling strategy", true},
        {"env_window", {"hemisphere"}, "hemisphere|lobe", "reference", "", "Monte Carlo: the windowed strategy's window", true},
        {"mis_compensation", {0.0}, ">=0", "reference", "", "Monte Carlo: MIS compensation (kappa samples)", true},
    };
    return table;
}

std::vector<std::string> OptionInfo::choices() const {
    std::vector<std::string> out;
    if (!enumerated()) return out;
    size_t start = 0;
    for (size_t bar; (bar = values.find('|', start)) != std::string::npos; start = bar + 1)
        out.push_back(values.substr(start, bar - start));
    out.push_back(values.substr(start));
    return out;
}

bool OptionInfo::read_by(const std::string& method) const {
    if (methods == "all") return true;
    size_t start = 0;
    for (size_t comma; start <= methods.size(); start = comma + 1) {
        comma = methods.find(',', start);
        if (comma == std::string::npos) comma = methods.size();
        if (methods.compare(start, comma - start, method) == 0 && comma - start == method.size()) return true;
    }
    return false;
}

const OptionInfo& option_info(const std::string& key) {
    for (const auto& o : option_catalog())
        if (o.key == key) return o;
    throw std::logic_error("option '" + key + "' is not in the option table (renderers/option_table.cpp)");
}

std::string option_value_text(const OptionValue& v) {
    struct Text {
        std::string operator()(std::monostate) const { return ""; }
        std::string operator()(int i) const { return std::to_string(i); }
        std::string operator()(double d) const { return fmt::format("{}", d); } // shortest: "0.0008", "10000"
        std::string operator()(const std::string& s) const { return s; }
        std::string operator()(Vec3f c) const { return fmt::format("{},{},{}", c.x, c.y, c.z); }
    };
    return std::visit(Text{}, v);
}

std::string OptionInfo::default_text() const {
    std::string text = std::holds_alternative<std::monostate>(defaults.value) ? defaults.note : option_value_text(defaults.value);
    std::string cases;
    for (const DefaultCase& c : defaults.cases) cases += (cases.empty() ? "" : "; ") + c.when + ": " + option_value_text(c.value);
    return cases.empty() ? text : text + " (" + cases + ")";
}

namespace {
// A case's `when` against the reader and the other options: "sampled", "shading=fragment", "spp set".
bool case_holds(const DefaultCase& c, const OptionMap& o, const std::string& reader) {
    if (c.when.size() > 4 && c.when.compare(c.when.size() - 4, 4, " set") == 0) return o.has(c.when.substr(0, c.when.size() - 4));
    const size_t eq = c.when.find('=');
    if (eq == std::string::npos) {
        if (reader.empty())
            throw std::logic_error("option default differs by reader ('" + c.when + "'): read it with the method or scene");
        return c.when == reader;
    }
    const std::string other = c.when.substr(0, eq);
    return o.get_string(other).value_or(option_value_text(option_default(o, other, reader))) == c.when.substr(eq + 1);
}

template <class T> const T& typed_default(const OptionMap& o, const std::string& key, const std::string& reader) {
    const OptionValue& v = option_default(o, key, reader);
    if (!std::holds_alternative<T>(v))
        throw std::logic_error("option '" + key + "': read as another type than its default in the option table");
    return std::get<T>(v);
}
} // namespace

const OptionValue& option_default(const OptionMap& o, const std::string& key, const std::string& reader) {
    const OptionDefault& d = option_info(key).defaults;
    for (const DefaultCase& c : d.cases)
        if (case_holds(c, o, reader)) return c.value;
    return d.value;
}

int option_int(const OptionMap& o, const std::string& key, const std::string& reader) {
    if (auto v = o.get_int(key)) return *v;
    return typed_default<int>(o, key, reader);
}

double option_double(const OptionMap& o, const std::string& key, const std::string& reader) {
    if (auto v = o.get_double(key)) return *v;
    return typed_default<double>(o, key, reader);
}

Vec3f option_vec3(const OptionMap& o, const std::string& key, const std::string& reader) {
    if (auto v = o.get_vec3(key)) return *v;
    return typed_default<Vec3f>(o, key, reader);
}

std::string option_string(const OptionMap& o, const std::string& key, const std::string& reader) {
    if (auto v = o.get_string(key)) return *v;
    return typed_default<std::string>(o, key, reader);
}

std::string option_choice(const OptionMap& o, const std::string& key, const std::string& reader) {
    const OptionInfo& info = option_info(key);
    if (!info.enumerated()) throw std::logic_error("option '" + key + "' is not an enumeration");
    if (auto v = o.get_choice(key, info.choices())) return *v;
    return typed_default<std::string>(o, key, reader);
}

std::string glsl_value_name(const OptionInfo& info, const std::string& value) {
    std::string name = info.glsl_define + "_";
    for (char c : value)
        name += std::isalnum(static_cast<unsigned char>(c)) ? char(std::toupper(static_cast<unsigned char>(c))) : '_';
    return name;
}

namespace {
size_t index_in_table(const OptionInfo& info, const std::string& value) {
    auto choices = info.choices();
    auto it = std::find(choices.begin(), choices.end(), value);
    if (it == choices.end()) {
        std::string valid;
        for (const auto& c : choices) valid += (valid.empty() ? "" : ", ") + c;
        throw UsageError("option '" + info.key + "': unknown value '" + value + "'; valid: " + valid);
    }
    return size_t(it - choices.begin());
}

const OptionInfo& shader_option(const std::string& key) {
    const OptionInfo& info = option_info(key);
    if (info.glsl_define.empty()) throw std::logic_error("option '" + key + "' selects no shader code");
    return info;
}
} // namespace

std::map<std::string, std::string> glsl_defines(const std::map<std::string, std::string>& selections) {
    std::map<std::string, std::string> defs;
    for (const auto& info : option_catalog()) {
        if (info.glsl_define.empty()) continue;
        auto choices = info.choices();
        for (size_t i = 0; i < choices.size(); ++i) defs[glsl_value_name(info, choices[i])] = std::to_string(i);
    }
    for (const auto& [key, value] : selections) {
        const OptionInfo& info = shader_option(key);
        defs[info.glsl_define] = std::to_string(index_in_table(info, value));
    }
    return defs;
}

std::map<std::string, std::string> shader_selections(const OptionMap& o, const std::string& method) {
    std::map<std::string, std::string> out;
    for (const auto& info : option_catalog())
        if (!info.glsl_define.empty() && info.read_by(method)) out[info.key] = option_choice(o, info.key);
    return out;
}

int ssaa_of(const OptionMap& o) { return option_int(o, "ssaa", "mobile"); }

std::map<std::string, std::string> glsl_selection_names(const std::map<std::string, std::string>& selections) {
    std::map<std::string, std::string> out;
    for (const auto& [key, value] : selections) {
        const OptionInfo& info = shader_option(key);
        index_in_table(info, value);
        out[info.glsl_define] = glsl_value_name(info, value);
    }
    return out;
}

} // namespace iblcheck
