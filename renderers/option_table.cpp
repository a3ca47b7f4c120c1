#include "option_table.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "kernel/errors.h"

namespace iblcheck {

const std::vector<OptionInfo>& option_catalog() {
    // key, default, values, methods, GLSL define, description
    static const std::vector<OptionInfo> table = {
        {"roughness", "0.5", "0..1", "all", "", "perceptual roughness of the `sphere` scene (alpha = r^2)"},
        {"metallic", "0", "0..1", "all", "", "metalness of the `sphere` scene"},
        {"base_color", "1,1,1", "r,g,b", "all", "", "base colour of the `sphere` scene"},
        {"env_rotation", "0", "degrees", "all", "", "turns the environment about +Y"},
        {"frame", "0", "integer", "all", "", "frame of an animated scene (bumpy_sphere)"},
        {"bump_amplitude", "0.0008", ">=0", "all", "", "height of the bumpy_sphere normal detail"},
        {"roughness_bias", "0", "-1..1", "all", "", "stability: added to every sphere's roughness"},
        {"camera_shift", "0", "pixels x,y,0", "all", "", "stability: moves the camera by a fraction of a pixel"},
        {"bump_frequency", "200", ">0", "all", "", "spatial frequency of the bumpy_sphere normal detail (radius-1 units)"},
        {"ao", "1", "0..1", "mobile", "",
         "material ambient occlusion of every sphere: multiplies its diffuse lighting and indirect_irradiance (UE4; so, under a "
         "normalisation, its reflections)"},
        {"ssaa", "2 (shading=fragment: 1)", "1..16", "mobile,sampled", "",
         "n x n rays per pixel (silhouettes); shading=fragment: renders n x n times the pixels and averages them"},
        {"cube_size", "128 (sampled: 256)", "8..2048, power of two", "mobile,sampled", "", "base size of the cubemaps"},
        {"mips", "the full chain", "2..log2(cube_size)+1", "mobile", "",
         "levels of the prefiltered chain; by default all the layout holds (cube: down to 1x1); a count whose last level is "
         "below r = 1 (UE4's curve reaches it at mip log2(cube_size)-2) is refused"},
        {"prefilter_samples", "256", "1..65536", "mobile", "",
         "GGX samples per prefiltered texel (filtered importance sampling); against a 4096-sample bake, the noise is under 1 % "
         "of the default's error against the truth in studio, sunrise and interior and 3 % in sky_sun (64: up to 6 %)"},
        {"shading", "compute", "compute|fragment", "mobile", "SHADING",
         "compute: each pixel ray-traces the spheres, specular AA from neighbouring rays; fragment: sphere impostors "
         "in a graphics pipeline, MSAA 4x, specular AA from the hardware quads' dFdx/dFdy"},
        {"mip_mapping", "ue4", "ue4|filament|origin", "mobile", "MIP_MAPPING", "roughness <-> mip mapping"},
        {"env_brdf", "approx", "approx|lut", "mobile", "ENV_BRDF", "EnvBRDFApprox (Karis/Lazarov) or a DFG LUT pass"},
        {"lut_size", "64", "8..512", "mobile", "", "DFG LUT resolution (env_brdf=lut)"},
        {"diffuse", "sh9", "sh9|irradiance_cube", "mobile", "DIFFUSE", "diffuse irradiance representation"},
        {"dominant_dir", "off", "off|lagarde|filament", "mobile", "DOMINANT_DIR", "specular dominant direction"},
        {"lagarde_roughness", "alpha", "alpha|perceptual", "mobile", "LAGARDE_ROUGHNESS",
         "dominant_dir=lagarde: the roughness its formula is fed: alpha = r^2 (Frostbite's listing 22/24, as EEVEE) or the "
         "perceptual r (as some ports)"},
        {"normalization", "off", "off|ue4|directional", "mobile", "NORMALIZATION",
         "UE4 mobile reflection normalisation (MixingAlpha); directional: the ratio at n (SH9 E(n) / the prefiltered chain's at "
         "n) instead of UE4's scalar one"},
        {"mix_begin_roughness", "0.1", "0..1", "mobile", "", "normalisation: roughness where mixing starts"},
        {"mix_end_roughness", "0.3", "0..1", "mobile", "", "normalisation: roughness where mixing is full"},
        {"mix_largest_weight", "10000", ">0", "mobile", "", "normalisation: clamp of the mixing weight"},
        {"indirect_irradiance", "sh9", "sh9 or a number", "mobile", "", "normalisation: lightmap/ILC brightness"},
        {"storage", "rgba16f", "rgba16f|rgba32f|rgbm8|r11g11b10|astc_hdr|astc_ldr_rgbm", "mobile", "STORAGE",
         "prefiltered cube storage; astc_*: encoded and decoded on the CPU by astcenc (libastcenc-dev), see astc_block"},
        {"astc_block", "4x4", "4x4|6x6", "mobile", "",
         "ASTC block footprint (storage=astc_*): 4x4 = 8 bits per texel, 6x6 = 3.56"},
        {"rgbm_range", "peak", "peak or >0", "mobile", "",
         "RGBM range (storage=rgbm8, astc_ldr_rgbm); peak: the base cube's largest value, as UE4.26 derives a mobile capture's "
         "MaxValueRGBM; the results give the range and the energy it clips"},
        {"env_layout", "cube", "cube|octahedral|equirect", "mobile", "ENV_LAYOUT",
         "layout of the prefiltered radiance: a cubemap (NxN x6) or one 2D texture, octahedral (2Nx2N) or lat-long (4Nx2N), with "
         "a 1-texel border per level"},
        {"precision", "highp", "highp|mediump", "mobile", "PRECISION", "mediump shades in float16_t"},
        {"fp16", "auto", "auto|native|emulated", "mobile", "",
         "precision=mediump: native float16_t, or emulated (fp32 rounded to fp16 per operation); auto: native if shaderFloat16"},
        {"specular_aa", "off", "off|tokuyoshi|rjump|toksvig", "mobile", "SPECULAR_AA",
         "specular anti-aliasing for low roughness"},
        {"specular_aa_variance", "0.25", ">=0", "mobile", "", "specular AA: screen-space variance scale"},
        {"specular_aa_threshold", "0.18", ">=0", "mobile", "", "specular AA: clamp of the added roughness"},
        {"samples", "64", "1..65536", "sampled", "", "GGX samples per ray"},
        {"min_lod", "0", ">=0", "sampled", "", "lowest mip a sample may read"},
        {"mip_clamp", "roughness", "roughness|off", "sampled", "MIP_CLAMP",
         "roughness: no sample reads a level finer than a quarter of the GGX lobe, 2^lod >= alpha*cube_size/pi (seed 002's clamp "
         "of "
         "the lowest mip by roughness); off: only min_lod"},
        {"diffuse_roughness", "0.9", "0..1", "sampled", "", "roughness from which radiance blends to irradiance"},
        {"seed", "0", "integer", "sampled,reference", "", "random seed"},
        {"spp", "256", ">=1", "reference", "", "samples per pixel (selects the Monte Carlo integrator)"},
        {"integrator", "quadrature", "quadrature|monte_carlo", "reference", "",
         "quadrature truth (default; monte_carlo when spp is set)"},
        {"truth_tolerance", "0.001", ">0", "reference", "", "quadrature truth: the coarser level's per-pixel tolerance"},
        {"threads", "0", ">=0", "reference", "", "CPU threads (0: all)"},
        {"split_sum", "off", "off|exact|env_brdf_approx", "reference", "",
         "quadrature truth: off renders the truth; exact / env_brdf_approx the split sum's rungs of `iblcheck explain` "
         "(prefiltered radiance at n = v = R times the exact DFG or EnvBRDFApprox, plus the exact diffuse; the coarse level "
         "only; renderers/reference/quadrature/split_sum.h)"},
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

std::string option_choice(const OptionMap& o, const std::string& key) {
    const OptionInfo& info = option_info(key);
    if (!info.enumerated()) throw std::logic_error("option '" + key + "' is not an enumeration");
    return o.get_choice(key, info.default_value, info.choices());
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

int ssaa_of(const OptionMap& o) { return o.get_int("ssaa", option_choice(o, "shading") == "fragment" ? 1 : 2); }

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
