// Environment loading and the equirect convention (environment.h).
#include "renderers/environments/environment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <fmt/core.h>

#include "image_io/image_formats.h"
#include "kernel/errors.h"
#include "kernel/options.h"
#include "renderers/environments/procedural.h"

namespace iblcheck {

namespace {
constexpr double kPi = 3.14159265358979323846;
const std::vector<std::string> kBlenderNames = {"city",  "courtyard", "forest",  "interior",
                                                "night", "studio",    "sunrise", "sunset"};

std::string lower(std::string s) {
    for (auto& c : s) c = char(std::tolower((unsigned char)c));
    return s;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string valid_specs() {
    std::string out = "constant:R,G,B, constant:V, studio, sky_sun";
    for (const auto& n : kBlenderNames) out += ", blender:" + n;
    return out + ", or a path to an .exr/.hdr file";
}

// The renderers integrate radiance in 32-bit floats: a constant 1e38 overflowed the precompute's
// sums into an all-black render that passed and could be blessed, 3e37 into NaN. The sun of
// sky_sun is 5e4; 1e30 leaves eight orders of magnitude below float's 3.4e38 for the sums.
constexpr float kMaxRadiance = 1e30f;

std::string environment_name(const Environment& env) {
    return "environment '" + env.spec + "'" + (env.source_path.empty() ? "" : " (" + env.source_path + ")");
}

void check_radiance(const Environment& env) {
    const cv::Mat& m = env.equirect;
    for (int y = 0; y < m.rows; ++y) {
        const float* p = m.ptr<float>(y);
        for (int i = 0; i < m.cols * 3; ++i)
            if (!(p[i] <= kMaxRadiance))
                throw InputError(fmt::format("{}: radiance {:g} at pixel ({}, {}) channel {} is above {:g} (the renderers' "
                                             "float sums overflow)",
                                             environment_name(env), p[i], i / 3, y, i % 3, kMaxRadiance));
    }
}

void finish(Environment& env) {
    check_radiance(env);
    if (env.equirect.cols != 2 * env.equirect.rows)
        throw InputError(environment_name(env) + ": " + std::to_string(env.equirect.cols) + "x" +
                         std::to_string(env.equirect.rows) + " is not an equirect panorama (width must be 2 x height)");
    env.content_hash = fnv1a64_hex(env.equirect);
}

Environment load_file(const std::string& spec, const std::string& path) {
    Environment env;
    env.spec = spec;
    env.source_path = path;
    if (!std::filesystem::exists(path)) throw InputError("environment file '" + path + "' does not exist");
    imagefile::RawImage img;
    try {
        img = imagefile::read_raw(path, false);
    } catch (const InputError& e) {
        // read_raw's message starts with the path; say which environment it was.
        std::string why = e.what();
        if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
        throw InputError("environment file '" + path + "': " + why);
    }
    const int w = img.width, h = img.height, nch = img.channels;
    if (w <= 0 || h <= 0 || nch <= 0) throw InputError("environment file '" + path + "': empty image");
    const std::vector<float>& buf = img.data;
    env.equirect.create(h, w, CV_32FC3);
    long bad = 0;
    std::string first_bad;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* p = &buf[(size_t(y) * w + x) * nch];
            auto& out = env.equirect.at<cv::Vec3f>(y, x);
            for (int c = 0; c < 3; ++c) {
                float v = p[nch >= 3 ? c : 0];
                if (!std::isfinite(v)) {
                    if (bad++ == 0)
                        first_bad = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " + std::to_string(c) +
                                    " = " + (std::isnan(v) ? "NaN" : "Inf");
                    v = 0;
                } else if (v < 0) {
                    ++env.negatives_clamped;
                    v = 0;
                }
                out[c] = v;
            }
        }
    if (bad)
        throw InputError("environment file '" + path + "': " + std::to_string(bad) + " non-finite (NaN/Inf) values; first at " +
                         first_bad);
    finish(env);
    return env;
}

std::string find_blender(const std::string& name) {
    std::vector<std::string> tried;
    if (const char* dir = std::getenv("IBLCHECK_HDRI_DIR"); dir && *dir) tried.push_back(std::string(dir) + "/" + name + ".exr");
    tried.push_back("/usr/share/blender/datafiles/studiolights/world/" + name + ".exr");
#ifdef IBLCHECK_SOURCE_DIR
    tried.push_back(std::string(IBLCHECK_SOURCE_DIR) + "/.cache/blender-hdri/" + name + ".exr");
#endif
    for (const auto& p : tried)
        if (std::filesystem::exists(p)) return p;
    std::string list;
    for (const auto& p : tried) list += (list.empty() ? "" : ", ") + p;
    throw InputError("environment 'blender:" + name + "' not found (looked in " + list +
                     "); run scripts/setup.sh to extract Blender's HDRIs");
}
} // namespace

// FNV-1a, 64 bits (Fowler, Noll, Vo; draft-eastlake-fnv: offset basis 14695981039346656037, prime
// 1099511628211). The basis had lost a digit before issue 16's regeneration (every hash changed then).
std::string fnv1a64_hex(const cv::Mat& m) {
    uint64_t h = 14695981039346656037ull;
    for (int r = 0; r < m.rows; ++r) {
        const auto* p = m.ptr<unsigned char>(r);
        size_t n = size_t(m.cols) * m.elemSize();
        for (size_t i = 0; i < n; ++i) {
            h ^= p[i];
            h *= 1099511628211ull;
        }
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)h);
    return buf;
}

std::vector<EnvironmentInfo> environment_catalog() {
    std::vector<EnvironmentInfo> out = {
        {"constant:R,G,B", "Uniform radiance 0..1e30 (also constant:V); 64x32. constant:1 is the white furnace."},
        {"studio", "Procedural 1024x512 studio: dim tinted backdrop (ceiling 0.1-0.2, floor 0.04-0.06) with five "
                   "rectangular area lights of radiance 9-50 (warm key front-left, cool fill, top strip, rim, kicker)."},
        {"sky_sun", "Procedural 1024x512 sky gradient (zenith 0.2,0.35,0.75 to horizon 0.75,0.8,0.9), darker ground "
                    "(~0.1) and a sun disk of radius 1.25 deg and radiance ~5e4 (1e5 x the sky) at elevation 35 deg, "
                    "azimuth 150 deg (in front of and above the camera)."},
    };
    for (const auto& n : kBlenderNames)
        out.push_back({"blender:" + n, "Blender studio-light HDRI " + n +
                                           ".exr ($IBLCHECK_HDRI_DIR, /usr/share/blender/..., or .cache/blender-hdri "
                                           "from scripts/setup.sh)"});
    out.push_back(
        {"PATH.exr|PATH.hdr", "Any 2:1 equirect file; negatives clamped and counted, NaN/Inf and radiance above 1e30 rejected."});
    return out;
}

bool is_environment_file(const std::string& spec) {
    return spec.rfind("constant:", 0) != 0 && spec.rfind("blender:", 0) != 0 && spec != "studio" && spec != "sky_sun";
}

std::string environment_label(const std::string& spec, const std::string& name) {
    if (!is_environment_file(spec)) return spec;
    return name.empty() ? std::filesystem::path(spec).filename().string() : name;
}

Environment load_environment(const std::string& spec) {
    if (spec.rfind("constant:", 0) == 0) {
        OptionMap o;
        o.set("constant", spec.substr(9));
        Vec3f c = *o.get_vec3("constant"); // set just above
        if (c.x < 0 || c.y < 0 || c.z < 0) throw UsageError("environment '" + spec + "': radiance must be >= 0");
        Environment env;
        env.spec = spec;
        env.equirect = cv::Mat(32, 64, CV_32FC3, cv::Scalar(c.x, c.y, c.z));
        finish(env);
        return env;
    }
    if (spec == "studio" || spec == "sky_sun") {
        Environment env;
        env.spec = spec;
        env.equirect = spec == "studio" ? procedural::make_studio() : procedural::make_sky_sun();
        finish(env);
        return env;
    }
    if (spec.rfind("blender:", 0) == 0) {
        std::string name = spec.substr(8);
        if (std::find(kBlenderNames.begin(), kBlenderNames.end(), name) == kBlenderNames.end())
            throw UsageError("unknown environment '" + spec + "'; valid: " + valid_specs());
        return load_file(spec, find_blender(name));
    }
    std::string l = lower(spec);
    if (ends_with(l, ".exr") || ends_with(l, ".hdr")) return load_file(spec, spec);
    throw UsageError("unknown environment '" + spec + "'; valid: " + valid_specs());
}

void direction_to_uv(const float d[3], float& u, float& v) {
    double phi = std::atan2(double(d[0]), -double(d[2]));
    u = float(0.5 + phi / (2 * kPi));
    v = float(std::acos(std::clamp(double(d[1]), -1.0, 1.0)) / kPi);
}

void uv_to_direction(float u, float v, float d[3]) {
    double phi = (double(u) - 0.5) * 2 * kPi, theta = double(v) * kPi;
    double st = std::sin(theta);
    d[0] = float(st * std::sin(phi));
    d[1] = float(std::cos(theta));
    d[2] = float(-st * std::cos(phi));
}

void bilinear_equirect(const float* data, int W, int H, size_t stride, double u, double v, double rgb[3]) {
    double x = u * W - 0.5, y = v * H - 0.5;
    double fx0 = std::floor(x), fy0 = std::floor(y);
    double fx = x - fx0, fy = y - fy0;
    int x0 = int(fx0) % W;
    if (x0 < 0) x0 += W;
    int x1 = x0 + 1 == W ? 0 : x0 + 1;
    int y0 = std::clamp(int(fy0), 0, H - 1), y1 = std::clamp(int(fy0) + 1, 0, H - 1);
    const float* r0 = data + size_t(y0) * stride;
    const float* r1 = data + size_t(y1) * stride;
    const float *a = r0 + 3 * x0, *b = r0 + 3 * x1, *c = r1 + 3 * x0, *e = r1 + 3 * x1;
    for (int k = 0; k < 3; ++k) rgb[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * e[k]);
}

void sample_bilinear(const Environment& env, const float d_in[3], float rgb[3]) {
    float d[3] = {d_in[0], d_in[1], d_in[2]};
    if (env.rotation_deg != 0) {
        // The environment is rotated by +rotation_deg about +Y (right-handed), so look up R(-rot)·d.
        double a = -double(env.rotation_deg) * kPi / 180, c = std::cos(a), s = std::sin(a);
        double x = c * d_in[0] + s * d_in[2], z = -s * d_in[0] + c * d_in[2];
        d[0] = float(x), d[2] = float(z);
    }
    float u, v;
    direction_to_uv(d, u, v);
    const cv::Mat& m = env.equirect;
    double out[3];
    bilinear_equirect(m.ptr<float>(0), m.cols, m.rows, m.step1(), u, v, out);
    for (int k = 0; k < 3; ++k) rgb[k] = float(out[k]);
}

} // namespace iblcheck
