// Analytic scene: camera rays and sphere intersection, mirroring renderers/scenes/scene.h
// (the same convention on the CPU side, so all three methods see the same geometry).
#ifndef IBLCHECK_SCENE_GLSL
#define IBLCHECK_SCENE_GLSL

struct SphereGpu {
    vec4 center_radius;
    vec4 base_color_metallic;
    vec4 roughness_bump;   // roughness, bump amplitude, bump frequency, bump phase
#ifdef MATERIAL_AO
    vec4 ao_pad;           // x: material ambient occlusion (option ao); present only when a sphere has one
#endif
};

// The camera as scene_camera() returns it (the first four vec4 of SceneBuffer).
struct CameraGpu {
    vec4 eye_ortho;       // xyz eye, w: 1 orthographic, 0 perspective
    vec4 forward_half_h;  // xyz forward, w: orthographic half height
    vec4 right_tan_half;  // xyz right, w: tan(fov_y / 2)
    vec4 up_pad;          // xyz up
};

// A uniform block, not a storage buffer: lavapipe loads a storage buffer lane by lane, and every ray
// reads every sphere (renderers/mobile/gpu_scene.h has the measurement). Its fixed size is
// gpu_scene.h's kSceneSphereCapacity: what Vulkan's minimum maxUniformBufferRange holds.
#define SCENE_SPHERE_CAPACITY 254
layout(binding = 0, std140) uniform SceneBuffer {
    vec4 eye_ortho;       // xyz eye, w: 1 orthographic, 0 perspective
    vec4 forward_half_h;  // xyz forward, w: orthographic half height
    vec4 right_tan_half;  // xyz right, w: tan(fov_y / 2)
    vec4 up_pad;          // xyz up
    uvec4 counts;         // x: sphere count
    SphereGpu spheres[SCENE_SPHERE_CAPACITY];
} scene;

CameraGpu scene_camera() { return CameraGpu(scene.eye_ortho, scene.forward_half_h, scene.right_tan_half, scene.up_pad); }

// scene.h: ndc = (2·px/W − 1, 1 − 2·py/H); orthographic: parallel rays from the image plane,
// perspective: from the eye.
void camera_ray_of(CameraGpu cam, vec2 p, vec2 size, out vec3 origin, out vec3 dir) {
    vec2 ndc = vec2(2.0 * p.x / size.x - 1.0, 1.0 - 2.0 * p.y / size.y);
    float aspect = size.x / size.y;
    vec3 f = cam.forward_half_h.xyz, r = cam.right_tan_half.xyz, u = cam.up_pad.xyz;
    if (cam.eye_ortho.w > 0.5) {
        float hh = cam.forward_half_h.w;
        origin = cam.eye_ortho.xyz + r * (ndc.x * hh * aspect) + u * (ndc.y * hh);
        dir = f;
    } else {
        float th = cam.right_tan_half.w;
        origin = cam.eye_ortho.xyz;
        dir = normalize(f + r * (ndc.x * th * aspect) + u * (ndc.y * th));
    }
}
void camera_ray(vec2 p, vec2 size, out vec3 origin, out vec3 dir) { camera_ray_of(scene_camera(), p, size, origin, dir); }

// Nearest hit in front of the origin; returns the sphere index or −1.
int intersect_scene(vec3 o, vec3 d, out float t_hit) {
    int best = -1;
    t_hit = 1e30;
    for (uint i = 0u; i < scene.counts.x; ++i) {
        vec3 c = scene.spheres[i].center_radius.xyz;
        float rad = scene.spheres[i].center_radius.w;
        vec3 oc = o - c;
        float b = dot(oc, d);
        float q = dot(oc, oc) - rad * rad;
        float disc = b * b - q;
        if (disc < 0.0) continue;
        float t = -b - sqrt(disc);
        if (t > 0.0 && t < t_hit) {
            t_hit = t;
            best = int(i);
        }
    }
    return best;
}

// Animated normal detail (bumpy_sphere): a height field h = A sin(f x + φ) sin(f y + 0.7 φ) on the
// surface, with its exact gradient; the normal tilts by the gradient's tangential part,
//   n' = normalize(n − (∇h − (∇h·n) n))      (Blinn 1978, "Simulation of Wrinkled Surfaces").
vec3 bump_normal(vec3 p, vec3 n, vec4 roughness_bump) {
    float amp = roughness_bump.y, f = roughness_bump.z, phase = roughness_bump.w;
    if (amp <= 0.0) return n;
    float sx = sin(f * p.x + phase), cx = cos(f * p.x + phase);
    float sy = sin(f * p.y + 0.7 * phase), cy = cos(f * p.y + 0.7 * phase);
    vec3 grad = amp * f * vec3(cx * sy, sx * cy, 0.0);
    return normalize(n - (grad - dot(grad, n) * n));
}

// The shading normal and view vector of the surface under pixel position p (pixel units);
// false for a miss. Used for the pixel's own rays and, by specular AA, its neighbours'.
bool surface_at(vec2 p, vec2 size, out int id, out vec3 n, out vec3 v) {
    vec3 o, d;
    camera_ray(p, size, o, d);
    float t;
    id = intersect_scene(o, d, t);
    if (id < 0) return false;
    vec3 pos = o + d * t;
    vec3 c = scene.spheres[id].center_radius.xyz;
    n = bump_normal(pos - c, normalize(pos - c), scene.spheres[id].roughness_bump);
    v = -d;
    return true;
}

#endif
