#version 460
// Pass 5, shading=fragment, vertex stage: one instance per sphere, a 4-vertex strip covering its
// projection (impostor.glsl). Clip space: Vulkan's y points down as the pixel rows do.
#include "split_sum.glsl"
#include "impostor.glsl"
#if SHADING != SHADING_FRAGMENT
#error "shade_spheres.frag and .vert are the shading=fragment pass (renderers/option_table.cpp)"
#endif

// The camera and the sphere, flat: the fragment stage reads them from here, never from the scene
// buffer (impostor.glsl says why).
layout(location = 0) flat out vec4 camera_out[4];
layout(location = 4) flat out vec4 sphere_out[3];

void main() {
    vec2 corner = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1)) * 2.0 - 1.0;
    vec2 size = vec2(pc.width, pc.height);
    CameraGpu cam = scene_camera();
    SphereGpu s = scene.spheres[gl_InstanceIndex];
    camera_out = vec4[4](cam.eye_ortho, cam.forward_half_h, cam.right_tan_half, cam.up_pad);
    sphere_out = vec4[3](s.center_radius, s.base_color_metallic, s.roughness_bump);
    vec2 px = impostor_corner(cam, s, corner, size);
    gl_Position = vec4(px / size * 2.0 - 1.0, 0.5, 1.0);
}
