// Built-in analytic scenes (see scene.h for the camera convention).
//
// Material defaults for the scenes that read the material options: the option table's, per scene
// (`sphere`, `grazing`: roughness 0.5, metallic 0, base_color 1,1,1, a white dielectric: Lambert with
// albedo 1 plus the F0 = 0.04 specular lobe; `bumpy_sphere`, `sphere_field`: a smooth metal). The
// multi-sphere scenes fix their own materials (that is what they are for); see the catalog descriptions.
#include "renderers/scenes/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "renderers/option_table.h"

namespace iblcheck {

namespace {

struct SceneDef {
    const char* name;
    const char* description;
    Scene (*build)(const OptionMap&);
};

// The material options as `scene` reads them (the option table holds each scene's defaults). A value
// outside [0, 1] was set (every default is inside), so its text is there to quote.
Material material_from_options(const OptionMap& o, const char* scene) {
    Material m;
    m.roughness = float(option_double(o, "roughness", scene));
    m.metallic = float(option_double(o, "metallic", scene));
    m.base_color = option_vec3(o, "base_color", scene);
    if (m.roughness < 0 || m.roughness > 1)
        throw UsageError("option 'roughness': " + o.get_string("roughness").value() + " is outside [0, 1]");
    if (m.metallic < 0 || m.metallic > 1)
        throw UsageError("option 'metallic': " + o.get_string("metallic").value() + " is outside [0, 1]");
    for (float c : {m.base_color.x, m.base_color.y, m.base_color.z})
        if (c < 0 || c > 1) throw UsageError("option 'base_color': " + o.get_string("base_color").value() + " is outside [0, 1]");
    return m;
}

std::string fmt_r(float r) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g", double(r));
    return buf;
}

// One radius-1 sphere of the material options' values for `reader` (sphere, bumpy_sphere).
Scene one_sphere(const OptionMap& o, const char* reader) {
    Scene s;
    s.name = "sphere";
    s.width = s.height = 128;
    s.camera.half_height = 1.1f; // radius-1 sphere fills 1/1.1 of the view
    Sphere sp;
    sp.center = {0, 0, 0};
    sp.radius = 1;
    sp.material = material_from_options(o, reader);
    s.spheres.push_back(sp);
    s.labels.push_back("sphere r=" + fmt_r(sp.material.roughness));
    return s;
}

Scene build_sphere(const OptionMap& o) { return one_sphere(o, "sphere"); }

Scene build_roughness_sweep(const OptionMap& o) {
    Scene s;
    s.name = "roughness_sweep";
    s.width = 11 * 48;
    s.height = 2 * 48;
    s.camera.half_height = 1.0f;              // 2 world units tall, 11 wide: one unit per sphere cell
    Vec3f metal_color{0.95f, 0.64f, 0.54f};   // copper
    Vec3f dielectric_color{0.5f, 0.5f, 0.5f}; // mid grey
    for (int row = 0; row < 2; ++row) {
        for (int i = 0; i <= 10; ++i) {
            Sphere sp;
            sp.center = {float(-5.0 + i), row == 0 ? 0.5f : -0.5f, 0};
            sp.radius = 0.45f;
            sp.material.roughness = float(i) / 10.0f;
            sp.material.metallic = row == 0 ? 1.0f : 0.0f;
            sp.material.base_color = row == 0 ? metal_color : dielectric_color;
            s.spheres.push_back(sp);
            s.labels.push_back(std::string(row == 0 ? "metal" : "dielectric") + " r=" + fmt_r(sp.material.roughness));
        }
    }
    (void)o;
    return s;
}

Scene furnace_row(const std::string& name, float metallic, const char* kind) {
    Scene s;
    s.name = name;
    s.width = 5 * 64;
    s.height = 64;
    s.camera.half_height = 0.5f; // one unit tall, five wide
    for (int i = 0; i < 5; ++i) {
        Sphere sp;
        sp.center = {float(-2.0 + i), 0, 0};
        sp.radius = 0.45f;
        sp.material.roughness = float(i) * 0.25f;
        sp.material.metallic = metallic;
        sp.material.base_color = {1, 1, 1};
        s.spheres.push_back(sp);
        s.labels.push_back(std::string(kind) + " r=" + fmt_r(sp.material.roughness));
    }
    return s;
}

Scene build_furnace(const OptionMap&) { return furnace_row("furnace", 1.0f, "metal"); }
Scene build_furnace_dielectric(const OptionMap&) { return furnace_row("furnace_dielectric", 0.0f, "dielectric"); }

Scene build_grazing(const OptionMap& o) {
    Scene s;
    s.name = "grazing";
    s.width = s.height = 128;
    // A close-up of the right limb of a radius-1 sphere: x in [0.74, 1.06], y in [-0.16, 0.16].
    s.camera.eye = {0.9f, 0, 5};
    s.camera.target = {0.9f, 0, 0};
    s.camera.half_height = 0.16f;
    Sphere sp;
    sp.material = material_from_options(o, "grazing");
    s.spheres.push_back(sp);
    s.labels.push_back("grazing r=" + fmt_r(sp.material.roughness));
    return s;
}

// Animated normal detail for the temporal suite: the bumps (renderers/shaders/scene.glsl,
// bump_normal) move by kBumpPhasePerFrame radians each frame, a fixed time step. Their amplitude and
// frequency are options (defaults in the option table).
constexpr float kBumpPhasePerFrame = 0.9f;

Scene build_bumpy_sphere(const OptionMap& o) {
    Scene s = one_sphere(o, "bumpy_sphere");
    s.name = "bumpy_sphere";
    Sphere& sp = s.spheres[0];
    sp.bump_amplitude = float(option_double(o, "bump_amplitude", "bumpy_sphere"));
    sp.bump_frequency = float(option_double(o, "bump_frequency", "bumpy_sphere"));
    sp.bump_phase = kBumpPhasePerFrame * float(option_int(o, "frame", "bumpy_sphere"));
    s.labels[0] = "bumpy r=" + fmt_r(sp.material.roughness);
    return s;
}

// A field of small, smooth, low-roughness spheres drifting by sub-pixel steps (temporal suite,
// issue 18): geometric specular AA's own case (Tokuyoshi & Kaplanyan 2019), where the normal's
// curvature, not normal detail, packs the highlight into less than a pixel and moving geometry
// makes it crawl and blink. 8x8 spheres of radius 3.5 px on a 20 px grid at the default 128x128
// (pixel = 1/64 world unit), each with its own sub-pixel start offset and a drift of 0.30-0.45 px a
// frame along a 20° diagonal (so both axes move by fractions of a pixel); the grid reaches 80 px
// left of and above the view so drifting spheres keep it filled for 32+ frames.
constexpr int kFieldGrid = 8;
constexpr float kFieldPixel = 1.0f / 64.0f; // world units per pixel at 128x128, half-height 1
constexpr float kFieldRadiusPx = 3.5f;
constexpr float kFieldSpacingPx = 20.0f;
constexpr float kFieldDriftDeg = 20.0f;

// A deterministic value in [0, 1) per (index, salt) (PCG hash, Jarzynski & Olano 2020): integer
// arithmetic only, so every machine builds the same field.
float field_hash(uint32_t i, uint32_t salt) {
    uint32_t state = (i * 0x9E3779B9u + salt) * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return float(((word >> 22u) ^ word) >> 8) / 16777216.0f;
}

Scene build_sphere_field(const OptionMap& o) {
    Scene s;
    s.name = "sphere_field";
    s.width = s.height = 128;
    s.camera.half_height = 1.0f;
    Material m;
    m.roughness = float(option_double(o, "roughness", "sphere_field"));
    m.metallic = float(option_double(o, "metallic", "sphere_field"));
    m.base_color = option_vec3(o, "base_color", "sphere_field");
    if (m.roughness < 0 || m.roughness > 1)
        throw UsageError("option 'roughness': " + o.get_string("roughness").value() + " is outside [0, 1]");
    const float frame = float(option_int(o, "frame", "sphere_field"));
    const float dx = std::cos(kFieldDriftDeg * 3.14159265f / 180.0f), dy = std::sin(kFieldDriftDeg * 3.14159265f / 180.0f);
    for (int j = 0; j < kFieldGrid; ++j)
        for (int i = 0; i < kFieldGrid; ++i) {
            uint32_t k = uint32_t(j * kFieldGrid + i);
            float speed = 0.30f + 0.15f * field_hash(k, 1); // px per frame
            // Pixel position (x right, y down, relative to the view centre) at this frame.
            float px = -80.0f + kFieldSpacingPx * float(i) + field_hash(k, 2) + speed * frame * dx;
            float py = -80.0f + kFieldSpacingPx * float(j) + field_hash(k, 3) + speed * frame * dy;
            Sphere sp;
            sp.center = {px * kFieldPixel, -py * kFieldPixel, 0};
            sp.radius = kFieldRadiusPx * kFieldPixel;
            sp.material = m;
            s.spheres.push_back(sp);
            s.labels.push_back("field " + std::to_string(i) + "," + std::to_string(j) + " r=" + fmt_r(m.roughness));
        }
    return s;
}

const std::vector<SceneDef>& defs() {
    static const std::vector<SceneDef> d = {
        {"sphere",
         "One radius-1 sphere filling 91% of a 128x128 orthographic view (half-height 1.1) looking -Z. "
         "Material from options roughness/metallic/base_color; defaults r=0.5, metallic=0, base_color=1,1,1.",
         build_sphere},
        {"roughness_sweep",
         "528x96: two rows of 11 spheres (48 px cells, radius 0.45 of a 1-unit cell), roughness 0, 0.1, ..., 1 "
         "left to right. Top row metal (metallic=1, base_color=0.95,0.64,0.54 copper), bottom row dielectric "
         "(metallic=0, base_color=0.5 grey). Materials are fixed; labels 'metal r=0.3', 'dielectric r=0.3'.",
         build_roughness_sweep},
        {"furnace",
         "320x64: a row of 5 metal spheres (metallic=1, base_color=1, so F0=1), roughness 0, 0.25, 0.5, 0.75, 1 "
         "(64 px cells, radius 0.45). Meant for constant:1, where each pixel equals the directional albedo E(n.v, a).",
         build_furnace},
        {"furnace_dielectric",
         "320x64: as furnace but white dielectric (metallic=0, base_color=1): in constant:1 each pixel equals "
         "1 (Lambert) + the F0=0.04 specular albedo.",
         build_furnace_dielectric},
        {"grazing",
         "128x128 orthographic close-up of the limb of a radius-1 sphere (view x in [0.74,1.06], y in [-0.16,0.16]): "
         "most covered pixels have n.v < 0.6, many near 0. Material options as for sphere.",
         build_grazing},
        {"bumpy_sphere",
         "128x128: the sphere scene with moving high-frequency normal detail (analytic sine bumps, "
         "amplitude 0.0008, frequency 200, phase +0.9 rad per frame; options frame=N, bump_amplitude, bump_frequency). "
         "Defaults roughness 0.05, metallic 1: the low-roughness case where specular highlights sparkle and crawl.",
         build_bumpy_sphere},
        {"sphere_field",
         "128x128: 8x8 smooth spheres of radius 3.5 px on a 20 px grid, drifting 0.30-0.45 px a frame along a 20 degree "
         "diagonal (option frame=N), each from its own sub-pixel offset. Defaults roughness 0.05, metallic 1: "
         "sub-pixel highlights from curvature alone, geometric specular AA's case (temporal suite).",
         build_sphere_field},
    };
    return d;
}

} // namespace

std::vector<SceneInfo> scene_catalog() {
    std::vector<SceneInfo> out;
    for (const auto& d : defs()) out.push_back({d.name, d.description});
    return out;
}

const std::vector<std::string>& scene_option_keys() {
    static const std::vector<std::string> keys = {"roughness",      "metallic",       "base_color",   "frame", "bump_amplitude",
                                                  "bump_frequency", "roughness_bias", "camera_shift", "ao"};
    return keys;
}

namespace {
// Small perturbations for the stability analysis (issue 9): every sphere's roughness + bias
// (clamped to [0, 1]) and the camera moved by a fraction of a pixel of the scene's default size.
// Material AO (option ao) on every sphere of any scene.
void apply_ao(Scene& s, const OptionMap& o) {
    if (!o.has("ao")) return;
    float ao = float(option_double(o, "ao", s.name));
    if (!(ao >= 0 && ao <= 1)) throw UsageError("option 'ao': " + o.get_string("ao").value() + " is outside [0, 1]");
    for (Sphere& sp : s.spheres) sp.material.ao = ao;
}

void apply_perturbations(Scene& s, const OptionMap& o) {
    float bias = float(option_double(o, "roughness_bias", s.name));
    for (Sphere& sp : s.spheres) sp.material.roughness = std::clamp(sp.material.roughness + bias, 0.0f, 1.0f);
    Vec3f shift = option_vec3(o, "camera_shift", s.name); // pixels: "x,y,0" or one value for x and y
    if (shift.x == 0 && shift.y == 0) return;
    // Pixel size in world units at the scene's default size (orthographic: 2·half_height/height).
    Camera& c = s.camera;
    float px = 2.0f * c.half_height / float(s.height);
    if (!c.orthographic) px = 2.0f * std::tan(c.fov_y_deg * 3.14159265f / 360.0f) * 5.0f / float(s.height);
    Vec3f f{c.target.x - c.eye.x, c.target.y - c.eye.y, c.target.z - c.eye.z};
    float fl = std::sqrt(f.x * f.x + f.y * f.y + f.z * f.z);
    f = {f.x / fl, f.y / fl, f.z / fl};
    Vec3f r{f.y * c.world_up.z - f.z * c.world_up.y, f.z * c.world_up.x - f.x * c.world_up.z,
            f.x * c.world_up.y - f.y * c.world_up.x};
    float rl = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    r = {r.x / rl, r.y / rl, r.z / rl};
    Vec3f u{r.y * f.z - r.z * f.y, r.z * f.x - r.x * f.z, r.x * f.y - r.y * f.x};
    // +x moves the image content left by `shift.x` pixels: the camera moves right; +y moves it up.
    Vec3f d{(r.x * shift.x - u.x * shift.y) * px, (r.y * shift.x - u.y * shift.y) * px, (r.z * shift.x - u.z * shift.y) * px};
    c.eye = {c.eye.x + d.x, c.eye.y + d.y, c.eye.z + d.z};
    c.target = {c.target.x + d.x, c.target.y + d.y, c.target.z + d.z};
}
} // namespace

Scene build_scene(const std::string& name, const OptionMap& options) {
    for (const auto& d : defs())
        if (name == d.name) {
            Scene s = d.build(options);
            apply_perturbations(s, options);
            apply_ao(s, options);
            return s;
        }
    std::string valid;
    for (const auto& d : defs()) valid += (valid.empty() ? "" : ", ") + std::string(d.name);
    throw UsageError("unknown scene '" + name + "'; valid scenes: " + valid);
}

double intersect_sphere(const Sphere& s, Vec3f origin, Vec3f dir, double oc[3]) {
    // |o + t d - c|^2 = r^2 with |d| = 1: t^2 + 2 b t + c = 0
    oc[0] = double(origin.x) - s.center.x, oc[1] = double(origin.y) - s.center.y, oc[2] = double(origin.z) - s.center.z;
    double b = oc[0] * dir.x + oc[1] * dir.y + oc[2] * dir.z;
    double c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - double(s.radius) * s.radius;
    double disc = b * b - c;
    if (disc < 0) return INFINITY;
    double sq = std::sqrt(disc);
    double t = -b - sq;
    if (t <= 1e-6) t = -b + sq;
    return t <= 1e-6 ? INFINITY : t;
}

Hit intersect(const Scene& scene, Vec3f origin, Vec3f dir) {
    Hit best;
    double best_t = INFINITY;
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        double oc[3];
        double t = intersect_sphere(scene.spheres[i], origin, dir, oc);
        if (t >= best_t) continue;
        const double ox = oc[0], oy = oc[1], oz = oc[2];
        best_t = t;
        best.hit = true;
        best.sphere = int(i);
        best.t = float(t);
        double px = ox + t * dir.x, py = oy + t * dir.y, pz = oz + t * dir.z;
        double inv = 1.0 / std::sqrt(px * px + py * py + pz * pz);
        best.normal = {float(px * inv), float(py * inv), float(pz * inv)};
        best.position = {float(origin.x + t * dir.x), float(origin.y + t * dir.y), float(origin.z + t * dir.z)};
    }
    return best;
}

void bump_normal(const Sphere& s, const double p[3], const double n[3], double out[3]) {
    const double amp = s.bump_amplitude, f = s.bump_frequency, ph = s.bump_phase;
    if (amp <= 0) {
        out[0] = n[0], out[1] = n[1], out[2] = n[2];
        return;
    }
    const double sx = std::sin(f * p[0] + ph), cx = std::cos(f * p[0] + ph);
    const double sy = std::sin(f * p[1] + 0.7 * ph), cy = std::cos(f * p[1] + 0.7 * ph);
    const double g[3] = {amp * f * cx * sy, amp * f * sx * cy, 0.0};
    const double gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
    double m[3], l = 0;
    for (int i = 0; i < 3; ++i) m[i] = n[i] - (g[i] - gn * n[i]), l += m[i] * m[i];
    l = 1 / std::sqrt(l);
    for (int i = 0; i < 3; ++i) out[i] = m[i] * l;
}

void camera_ray(const Scene& scene, int width, int height, double px, double py, Vec3f& origin, Vec3f& dir) {
    const Camera& c = scene.camera;
    auto normalize = [](double x, double y, double z, double out[3]) {
        double l = std::sqrt(x * x + y * y + z * z);
        out[0] = x / l, out[1] = y / l, out[2] = z / l;
    };
    double f[3], r[3], u[3];
    normalize(double(c.target.x) - c.eye.x, double(c.target.y) - c.eye.y, double(c.target.z) - c.eye.z, f);
    // right = forward x world_up
    normalize(f[1] * c.world_up.z - f[2] * c.world_up.y, f[2] * c.world_up.x - f[0] * c.world_up.z,
              f[0] * c.world_up.y - f[1] * c.world_up.x, r);
    // up = right x forward
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    double nx = 2.0 * px / width - 1.0, ny = 1.0 - 2.0 * py / height;
    if (c.orthographic) {
        double hh = c.half_height, hw = hh * double(width) / height;
        origin = {float(c.eye.x + r[0] * nx * hw + u[0] * ny * hh), float(c.eye.y + r[1] * nx * hw + u[1] * ny * hh),
                  float(c.eye.z + r[2] * nx * hw + u[2] * ny * hh)};
        dir = {float(f[0]), float(f[1]), float(f[2])};
    } else {
        double t = std::tan(double(c.fov_y_deg) * 3.14159265358979323846 / 360.0);
        double ax = nx * t * double(width) / height, ay = ny * t;
        double d[3];
        normalize(f[0] + r[0] * ax + u[0] * ay, f[1] + r[1] * ax + u[1] * ay, f[2] + r[2] * ax + u[2] * ay, d);
        origin = c.eye;
        dir = {float(d[0]), float(d[1]), float(d[2])};
    }
}

} // namespace iblcheck
