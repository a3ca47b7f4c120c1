// Analytic scenes shared by all three methods (mobile, sampled, reference). A scene is a camera
// and a few spheres; every pixel is ray-traced against them (exact normals, no mesh), so the GPU
// and the CPU see the same geometry. Pixels that hit no sphere are black (0): the environment
// is seen only through reflections, so metrics measure lighting, not the backdrop.
//
// Camera convention (the GLSL in renderers/shaders/scene.glsl mirrors it): pixel (x, y), y down,
// sample position (x + sx, y + sy) with sx, sy in [0,1); ndc = (2·px/W − 1, 1 − 2·py/H).
//   orthographic: origin = eye + right·ndc.x·half_w + up·ndc.y·half_h, dir = forward
//   perspective:  origin = eye, dir = normalize(forward + right·ndc.x·tan(fov/2)·W/H + up·ndc.y·tan(fov/2))
// where half_w = half_h·W/H, forward = normalize(target − eye), right = normalize(forward × world_up),
// up = right × forward. World is Y-up, right-handed.
#pragma once
#include <string>
#include <vector>

#include "kernel/options.h"
#include "kernel/vec3.h"

namespace iblcheck {

struct Material {
    Vec3f base_color{1, 1, 1};
    float metallic = 0;
    float roughness = 0.5f; // perceptual; α = r²
    // Material ambient occlusion (option ao, every sphere): UE4 multiplies the diffuse indirect
    // lighting and the indirect_irradiance its mobile normalisation reads (seed 001). The mobile
    // method reads it; the reference and sampled methods refuse the option.
    float ao = 1.0f;
};

struct Sphere {
    Vec3f center;
    float radius = 1;
    Material material;
    // Animated-normal detail (temporal scenes); 0 amplitude = smooth sphere.
    float bump_amplitude = 0;
    float bump_frequency = 0;
    float bump_phase = 0;
};

struct Camera {
    bool orthographic = true;
    Vec3f eye{0, 0, 5};
    Vec3f target{0, 0, 0};
    Vec3f world_up{0, 1, 0};
    float half_height = 1.1f; // orthographic
    float fov_y_deg = 40.0f;  // perspective
};

struct Scene {
    std::string name;
    Camera camera;
    std::vector<Sphere> spheres;
    int width = 128; // default image size; --size overrides
    int height = 128;
    // Labels of the spheres in order (e.g. "metal r=0.3"), used by per-roughness metrics.
    std::vector<std::string> labels;
};

struct SceneInfo {
    std::string name;
    std::string description;
};

// The built-in scenes (`iblcheck list`).
std::vector<SceneInfo> scene_catalog();

// Material options every scene understands: roughness, metallic, base_color.
// Throws UsageError naming the scene and listing the valid ones.
Scene build_scene(const std::string& name, const OptionMap& options);

// The option keys build_scene reads (so callers can reject unknown keys).
const std::vector<std::string>& scene_option_keys();

// Ray–scene intersection used by the CPU methods: nearest hit along (o, d), d unit.
struct Hit {
    bool hit = false;
    int sphere = -1;
    float t = 0;
    Vec3f position, normal;
};
Hit intersect(const Scene& scene, Vec3f origin, Vec3f dir);
// Distance along (o, d), d unit, to the sphere's nearest surface in front of o (1e-6 onwards), or
// +infinity; also o − centre, from which callers take the hit point. Shared by intersect() and the
// reference integrator's culled loop, so both see the same arithmetic.
double intersect_sphere(const Sphere& s, Vec3f origin, Vec3f dir, double oc[3]);

// Animated normal detail (bumpy_sphere): the height field h = A sin(f x + φ) sin(f y + 0.7 φ) of the
// point p on the sphere relative to its centre (world units), with its exact gradient; the normal n
// tilts by the gradient's tangential part, n' = normalize(n − (∇h − (∇h·n) n)) (Blinn 1978). The
// shaders' scene.glsl evaluates the same field; this is the CPU definition the reference integrates.
// Returns n unchanged when the sphere has no bumps.
void bump_normal(const Sphere& s, const double p[3], const double n[3], double out[3]);

// Camera ray through (px, py) in pixel units (x + sx, y + sy); see the convention above.
void camera_ray(const Scene& scene, int width, int height, double px, double py, Vec3f& origin, Vec3f& dir);

} // namespace iblcheck
